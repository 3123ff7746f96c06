#pragma once
/// \file result.hpp
/// Bad data (files, user input) is reported as a value, never an assert or
/// a crash: a Result carries either the value or one Error that says what
/// kind of failure, where and what (the Jolt `Result::SetError` pattern).
/// The engine, the loader, the CLI and the editor all use it; callers branch
/// on `kind` and compose on `where`, never on the message's text.

#include <cassert>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace stepwise {

/// What kind of failure: decides a command's exit code and how a caller
/// recovers.
enum class ErrorKind : std::uint8_t {
    BadInput,     ///< a file, an argument or an edit breaks a rule (exit 2)
    Io,           ///< a file cannot be read or written (exit 2)
    Diverged,     ///< the simulation produced a non-finite value (exit 3)
    Environment,  ///< the machine lacks what is needed: a display, an OpenGL context (exit 1)
};

struct Error {
    std::string message;  ///< what is wrong, for a person
    /// Where: a JSON pointer ("/entities/3/polygon/vertices/2"), a field
    /// ("length"), a file or an option, outermost first; empty when the
    /// message already says it. Callers prepend their own place with within().
    std::string where;
    ErrorKind kind = ErrorKind::BadInput;

    /// "WHERE: MESSAGE", or MESSAGE when there is no place.
    std::string text() const { return where.empty() ? message : where + ": " + message; }
    /// The same error one level out: `outer` goes in front of `where`,
    /// joined by `separator` ("/" for JSON pointers, "." for fields).
    Error within(const std::string& outer, const char* separator = "/") const {
        return Error{message, where.empty() ? outer : outer + separator + where, kind};
    }

    friend bool operator==(const Error&, const Error&) = default;
};

template <class T>
class [[nodiscard]] Result {
public:
    Result(T value) : data_(std::move(value)) {}
    Result(Error error) : data_(std::move(error)) {}

    bool ok() const { return data_.index() == 0; }
    explicit operator bool() const { return ok(); }
    T& value() { assert(ok()); return std::get<0>(data_); }
    const T& value() const { assert(ok()); return std::get<0>(data_); }
    T& operator*() { return value(); }
    const T& operator*() const { return value(); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    /// The whole message, place included ("WHERE: MESSAGE").
    std::string error() const { return failure().text(); }
    const Error& failure() const { assert(!ok()); return std::get<1>(data_); }

private:
    std::variant<T, Error> data_;
};

template <>
class [[nodiscard]] Result<void> {
public:
    Result() = default;
    Result(Error error) : error_(std::move(error)) {}
    bool ok() const { return !error_; }
    explicit operator bool() const { return ok(); }
    /// The whole message, place included ("WHERE: MESSAGE").
    std::string error() const { return failure().text(); }
    const Error& failure() const { assert(error_); return *error_; }

private:
    std::optional<Error> error_;
};

} // namespace stepwise
