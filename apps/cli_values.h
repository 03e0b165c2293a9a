// Checks shared by the programs' CLI11 command lines (dpc-demo, dpc-bake, dpc-analyze).
// Main thread, while the command line is parsed; allocates.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace dpc {

/// Refuses an empty value ("--ir-out ''", "--duration=") for every option of `app` that
/// takes one, positionals included, with CLI11's ValidationError "--ir-out: is empty". Without
/// it CLI11 reads an empty number as "not given" and an empty path means "no such output":
/// the flag would be ignored without a word. Call once every option is added; the check runs
/// before the options' own validators.
inline void refuseEmptyValues(CLI::App& app) {
  const CLI::Validator notEmpty(
      [](std::string& value) { return value.empty() ? std::string("is empty") : std::string(); },
      "", "NOT_EMPTY");
  for (CLI::Option* option : app.get_options())
    if (option->get_type_size_max() > 0) option->transform(notEmpty);
}

}  // namespace dpc
