// iplan: the command-line tool of the iplan robot cell.
#include <cstdlib>
#include <iostream>
#include <map>

#include "command_registry.h"

namespace iplan::cli {
namespace {
std::map<std::string, RegisterFn>& Registry() {
  static std::map<std::string, RegisterFn> registry;
  return registry;
}
int& ExitCode() {
  static int code = 0;
  return code;
}
}  // namespace

bool RegisterCommand(const std::string& order_key, RegisterFn fn) {
  Registry().emplace(order_key, std::move(fn));
  return true;
}

void SetExitCode(int code) { ExitCode() = code; }

}  // namespace iplan::cli

int main(int argc, char** argv) {
  CLI::App app{
      "iplan: intention-aware motion planning for a robot arm working beside a "
      "person.\nRun `iplan COMMAND --help` for the options of each command."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("iplan 0.1.0"));
  for (auto& [key, fn] : iplan::cli::Registry()) fn(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::cerr << "iplan: error: " << e.what() << "\n";
    return 1;
  }
  return iplan::cli::ExitCode();
}
