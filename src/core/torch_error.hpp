#pragma once
// LibTorch's exceptions carry a C++ backtrace in what(); a user is shown one line.
#include <c10/util/Exception.h>

#include <string>

namespace iesrgs {

// The first line of a LibTorch error's message, without its backtrace.
std::string torch_error_line(const c10::Error& error);

// One line for the exception being handled (call it inside a catch block): "out of memory",
// with the size LibTorch asked for when it says, for an allocation that failed; "PATH: reason"
// for a std::filesystem error; the message of any other exception.
std::string current_exception_message();

// Whether the exception being handled (call it inside a catch block) is an allocation that
// failed: std::bad_alloc, or LibTorch's allocator's error.
bool handling_out_of_memory();

}  // namespace iesrgs
