// Errors that come from data (a file, a scene description, user input), as opposed to programming
// mistakes, which are asserts. Library code throws InputError; the CLI turns it into one line on stderr
// and exit code 1. Nothing in src/ calls exit() or abort() because of what a file contains.
#pragma once

#include <stdexcept>
#include <string>

namespace pointrast {

class InputError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// The GPU lacks a feature a method needs (an extension, 64-bit atomics, memory). Also one clear line.
class UnsupportedError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// The GPU stopped making progress (a submission did not finish in time, or the device was lost). Unlike
// UnsupportedError it says nothing about the method: every later submission on the device is suspect.
class DeviceFault : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// The user interrupted long work (Ctrl-C): unwinding removes what was half written; the CLI exits 130.
class Interrupted : public std::runtime_error {
public:
  Interrupted() : std::runtime_error("interrupted") {}
};

} // namespace pointrast
