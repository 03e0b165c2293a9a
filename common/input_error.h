// InputError: a mistake in the user's input, named by file and field.
//
// Thrown by loaders on the control thread (never on the audio thread). what() is one line of
// the form "FILE: FIELD: problem", e.g. "hall.json: materials.concrete.absorption[3]: 1.7 is
// outside [0, 1]", ready to print as is. Apps catch it, print it, exit non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace dpc {

class InputError : public std::runtime_error {
 public:
  /// file: path as the user gave it; field: dotted JSON path or "" for the whole file.
  InputError(const std::string& file, const std::string& field, const std::string& problem)
      : std::runtime_error(printable(field.empty() ? file + ": " + problem
                                                   : file + ": " + field + ": " + problem)),
        file_(file),
        field_(field),
        problem_(problem) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  /// The problem alone, without the file and the field.
  const std::string& problem() const { return problem_; }

 private:
  /// Control characters (from keys or file names) escaped as \xNN so the line is safe to print.
  static std::string printable(const std::string& s) {
    static const char* hex = "0123456789abcdef";
    std::string out;
    for (const char c : s) {
      const auto u = static_cast<unsigned char>(c);
      if (u < 0x20 || u == 0x7f) {
        out += "\\x";
        out += hex[u >> 4];
        out += hex[u & 15];
      } else {
        out += c;
      }
    }
    return out;
  }
  std::string file_, field_, problem_;
};

}  // namespace dpc
