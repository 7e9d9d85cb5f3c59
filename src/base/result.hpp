// The one shape for operations that can fail with a message a user reads: Result<T> holds a value or an Error,
// Status (Result<void>) just success or an Error. The message names the file, line or parameter and the reason
// in one line ("museum.xml:12: <resource> is empty"); callers add context, never replace it. Exceptions stay for
// programmer errors and library boundaries; what a user's input can cause comes back as a Result.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace arwb {

struct Error {
  std::string message;
};
inline Error fail(std::string message) { return Error{std::move(message)}; }

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::in_place_index<0>, std::move(value)) {}   // NOLINT: implicit, as `return value;`
  Result(Error e) : v_(std::in_place_index<1>, std::move(e)) {}       // NOLINT: implicit, as `return fail(..);`

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  // The value; only when ok().
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  // The message; empty when ok().
  const std::string& error() const {
    static const std::string none;
    return ok() ? none : std::get<1>(v_).message;
  }

 private:
  std::variant<T, Error> v_;
};

template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error e) : error_(std::move(e.message)), ok_(false) {}   // NOLINT: implicit, as `return fail(..);`
  bool ok() const { return ok_; }
  explicit operator bool() const { return ok_; }
  const std::string& error() const { return error_; }

 private:
  std::string error_;
  bool ok_ = true;
};
using Status = Result<void>;

}  // namespace arwb
