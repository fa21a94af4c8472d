// Result<T>: a value or an Error. Core libraries return it instead of throwing; exceptions
// are used only at the edges (command-line tools, file loading helpers for them).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace ecsim {

enum class ErrorCode : std::uint8_t {
  kInvalidArgument,
  kTruncated,  // input shorter than its header says
  kTooLarge,   // would not fit (frame, buffer, register file)
  kMalformed,  // structurally wrong input (bad type field, bad length)
  kNotFound,
  kUnsupported,
  kIo,          // operating-system call failed
  kPermission,  // missing privilege (CAP_NET_ADMIN, CAP_NET_RAW, ...)
  kTimeout,
  kWorkingCounter,  // a datagram came back with an unexpected WKC
  kState,           // operation not allowed in the current state
  kAborted,         // peer aborted (SDO abort, AL error)
  kParse,           // file content could not be parsed (names file and line)
};

std::string_view toString(ErrorCode code);

// An error with a code and a human-readable context ("frame byte 14: datagram length 2000
// exceeds frame"). Errors are off the cyclic path, so the string may allocate.
struct Error {
  ErrorCode code{ErrorCode::kInvalidArgument};
  std::string context;

  std::string message() const { return std::string(toString(code)) + ": " + context; }
};

inline Error makeError(ErrorCode code, std::string context) {
  return Error{code, std::move(context)};
}

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : data_(std::in_place_index<0>, std::move(value)) {}      // NOLINT implicit
  Result(Error error) : data_(std::in_place_index<1>, std::move(error)) {}  // NOLINT implicit

  bool ok() const { return data_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & { return std::get<0>(data_); }
  const T& value() const& { return std::get<0>(data_); }
  T&& value() && { return std::get<0>(std::move(data_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Error& error() const { return std::get<1>(data_); }
  Error&& takeError() { return std::get<1>(std::move(data_)); }

  template <typename U>
  T valueOr(U&& fallback) const {
    return ok() ? value() : static_cast<T>(std::forward<U>(fallback));
  }

 private:
  std::variant<T, Error> data_;
};

template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT implicit

  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const Error& error() const { return error_; }
  Error&& takeError() { return std::move(error_); }

 private:
  Error error_{};
  bool ok_{true};
};

using Status = Result<void>;

inline Status okStatus() {
  return {};
}

}  // namespace ecsim

// Propagate an error from an expression returning Result<...>.
#define ECSIM_TRY(expr)                                                \
  do {                                                                 \
    auto ecsim_try_result_ = (expr);                                   \
    if (!ecsim_try_result_.ok()) return ecsim_try_result_.takeError(); \
  } while (false)

#define ECSIM_CONCAT_INNER_(a, b) a##b
#define ECSIM_CONCAT_(a, b) ECSIM_CONCAT_INNER_(a, b)
// ECSIM_ASSIGN_OR_RETURN(auto x, expr): declare x from the value of expr or return its error.
#define ECSIM_ASSIGN_OR_RETURN(decl, expr)                     \
  auto ECSIM_CONCAT_(ecsim_assign_, __LINE__) = (expr);        \
  if (!ECSIM_CONCAT_(ecsim_assign_, __LINE__).ok())            \
    return ECSIM_CONCAT_(ecsim_assign_, __LINE__).takeError(); \
  decl = std::move(ECSIM_CONCAT_(ecsim_assign_, __LINE__)).value()
