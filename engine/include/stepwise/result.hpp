#pragma once
/// \file result.hpp
/// Bad data (files, user input) is reported as a value, never an assert or
/// a crash: a Result carries either the value or one message that says where
/// and what (the Jolt `Result::SetError` pattern).

#include <cassert>
#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace stepwise {

struct Error {
    std::string message;

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
    T* operator->() { return &value(); }
    const std::string& error() const { assert(!ok()); return std::get<1>(data_).message; }

private:
    std::variant<T, Error> data_;
};

template <>
class [[nodiscard]] Result<void> {
public:
    Result() = default;
    Result(Error error) : error_(std::move(error.message)), failed_(true) {}
    bool ok() const { return !failed_; }
    explicit operator bool() const { return ok(); }
    const std::string& error() const { assert(failed_); return error_; }

private:
    std::string error_;
    bool failed_ = false;
};

} // namespace stepwise
