#pragma once
// Each subcommand lives in its own apps/cmd_<name>.cc and adds itself to the app.
// Callbacks report failure by throwing ss::InputError (exit 2) or ss::WorkError (exit 1).
#include <CLI/CLI.hpp>

namespace ss::apps {

void AddSynthCommand(CLI::App& app);
void AddReplayCommand(CLI::App& app);
void AddBankCommand(CLI::App& app);
void AddBenchCommand(CLI::App& app);
void AddConfigCommand(CLI::App& app);

}  // namespace ss::apps
