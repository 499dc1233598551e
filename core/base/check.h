#pragma once
// RECONAR_CHECK guards programmer errors only (broken invariants); input errors use Status.
#include <sstream>

namespace reconar::internal {

class CheckFailure {
 public:
  CheckFailure(const char* file, int line, const char* condition);
  [[noreturn]] ~CheckFailure();
  template <typename T>
  CheckFailure& operator<<(const T& value) {
    stream_ << value;
    return *this;
  }

 private:
  std::ostringstream stream_;
};

// Lets the macro below be used as an expression statement with a streamed message.
struct Voidify {
  void operator&(const CheckFailure&) {}
};

}  // namespace reconar::internal

#define RECONAR_CHECK(condition)                 \
  (condition) ? (void)0                          \
              : ::reconar::internal::Voidify() & \
                    ::reconar::internal::CheckFailure(__FILE__, __LINE__, #condition)
