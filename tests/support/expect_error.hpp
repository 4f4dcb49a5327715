#pragma once
// Runs `action` and returns the message of the iesrgs::Error it throws (a test failure when it
// throws nothing), so bad-input tests can check that the message names the file and the problem
// (`contains`).
#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"

namespace iesrgs::testing {

template <typename Action>
std::string error_message(Action&& action) {
  try {
    action();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an iesrgs::Error";
  return {};
}

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace iesrgs::testing
