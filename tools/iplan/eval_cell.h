// `iplan eval cell` (cmd_eval_cell.cc): added to `iplan eval` by
// cmd_eval.cc, which owns the `eval` command.
#pragma once

#include <CLI/CLI.hpp>

namespace iplan::cli {

/// Adds the `cell` subcommand (the episode benchmark) to `eval`.
void AddEvalCellCommand(CLI::App* eval);

}  // namespace iplan::cli
