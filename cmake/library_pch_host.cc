// The target that compiles the libraries' shared precompiled header (reconar_add_library_pch in
// cmake/ReconarHelpers.cmake); it holds no code.
