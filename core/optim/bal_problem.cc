#include "core/optim/bal_problem.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

namespace reconar {
namespace {

// Whitespace tokenizer that remembers the line of the last token, for error messages.
class Tokenizer {
 public:
  Tokenizer(const std::string& text, const std::string& name) : text_(text), name_(name) {}

  // Reads the next token as a double; `what` describes the expected value for errors.
  Status NextDouble(const char* what, double* value) {
    RECONAR_RETURN_IF_ERROR(NextToken(what));
    errno = 0;
    char* end = nullptr;
    *value = std::strtod(token_.c_str(), &end);
    if (end != token_.c_str() + token_.size() || errno == ERANGE || !std::isfinite(*value)) {
      return Error("expected a number for " + std::string(what) + ", got '" + token_ + "'");
    }
    return Status::Ok();
  }

  Status NextInt(const char* what, long long max_value, int* value) {
    RECONAR_RETURN_IF_ERROR(NextToken(what));
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(token_.c_str(), &end, 10);
    if (end != token_.c_str() + token_.size() || errno == ERANGE) {
      return Error("expected an integer for " + std::string(what) + ", got '" + token_ + "'");
    }
    if (v < 0 || v > max_value) {
      return Error(std::string(what) + " " + token_ + " out of range [0, " +
                   std::to_string(max_value) + "]");
    }
    *value = static_cast<int>(v);
    return Status::Ok();
  }

  Status Error(const std::string& reason) const {
    return FileError(StatusCode::kCorruptData, name_ + ":" + std::to_string(line_), reason);
  }

 private:
  Status NextToken(const char* what) {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
      } else if (c != ' ' && c != '\t' && c != '\r' && c != '\f' && c != '\v') {
        break;
      }
      ++pos_;
    }
    if (pos_ >= text_.size()) {
      return Error("unexpected end of file (truncated?) while reading " + std::string(what));
    }
    const size_t start = pos_;
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v') break;
      ++pos_;
    }
    token_.assign(text_, start, pos_ - start);
    return Status::Ok();
  }

  const std::string& text_;
  const std::string& name_;
  size_t pos_ = 0;
  int line_ = 1;
  std::string token_;
};

}  // namespace

Result<BalProblem> ParseBalProblem(const std::string& text, const std::string& name) {
  Tokenizer tok(text, name);
  // Bounds keep the array sizes (and Jacobian sizes) representable in int.
  constexpr long long kMaxCount = std::numeric_limits<int>::max() / 16;
  int num_cameras = 0, num_points = 0, num_observations = 0;
  RECONAR_RETURN_IF_ERROR(tok.NextInt("camera count", kMaxCount, &num_cameras));
  RECONAR_RETURN_IF_ERROR(tok.NextInt("point count", kMaxCount, &num_points));
  RECONAR_RETURN_IF_ERROR(tok.NextInt("observation count", kMaxCount, &num_observations));
  if (num_observations > 0 && (num_cameras == 0 || num_points == 0)) {
    return tok.Error("observations given but no cameras or no points");
  }
  // Each observation line has at least 8 bytes ("0 0 0 0\n"): a cheap bound against absurd counts.
  if (static_cast<size_t>(num_observations) > text.size() / 8 + 1 ||
      static_cast<size_t>(num_cameras) * 9 + static_cast<size_t>(num_points) * 3 >
          text.size() / 2 + 1) {
    return tok.Error("counts larger than the file can hold (truncated file or bad header)");
  }
  BalProblem problem;
  problem.observations.resize(static_cast<size_t>(num_observations));
  for (BalObservation& o : problem.observations) {
    RECONAR_RETURN_IF_ERROR(tok.NextInt("observation camera index", num_cameras - 1, &o.camera));
    RECONAR_RETURN_IF_ERROR(tok.NextInt("observation point index", num_points - 1, &o.point));
    RECONAR_RETURN_IF_ERROR(tok.NextDouble("observation x", &o.x));
    RECONAR_RETURN_IF_ERROR(tok.NextDouble("observation y", &o.y));
  }
  problem.cameras.resize(static_cast<size_t>(num_cameras) * BalProblem::kCameraSize);
  for (double& v : problem.cameras) {
    RECONAR_RETURN_IF_ERROR(tok.NextDouble("camera parameter", &v));
  }
  problem.points.resize(static_cast<size_t>(num_points) * BalProblem::kPointSize);
  for (double& v : problem.points) {
    RECONAR_RETURN_IF_ERROR(tok.NextDouble("point coordinate", &v));
  }
  return problem;
}

Result<BalProblem> ReadBalProblem(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return FileError(StatusCode::kNotFound, path, "cannot open BAL file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return FileError(StatusCode::kIoError, path, "read failed");
  return ParseBalProblem(buffer.str(), path);
}

}  // namespace reconar
