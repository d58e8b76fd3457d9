// SPDX-License-Identifier: Apache-2.0
#pragma once
// Errors that chromatrace's tools report to the user.
//
// InputError is bad input: a file, field, channel or option the user can fix. Commands turn it into one
// line on stderr and exit code 2. Its message always names where the problem is, e.g.
//   "scene.json: materials.red.roughness: must be in [0, 1], got 1.5".
// Anything else that escapes a command is a runtime failure (exit 1).

#include <stdexcept>
#include <string>
#include <string_view>

namespace ct {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `text` as one printable line: a newline becomes \n, a tab \t, any other control character (and DEL)
// \xHH, so that a file name or a library's message with line breaks in it stays one line of an error.
std::string one_line(std::string_view text);

}  // namespace ct
