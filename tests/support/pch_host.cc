// The target that compiles the tests' shared precompiled header (reconar_add_test_pch in
// cmake/ReconarHelpers.cmake); it holds no test.
