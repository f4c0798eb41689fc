#pragma once
// Each subcommand lives in its own apps/cmd_<name>.cc and adds itself to the app.
// Callbacks report failure by throwing ss::InputError (exit 2) or ss::WorkError (exit 1).
#include <CLI/CLI.hpp>

namespace ss::apps {

void AddSynthCommand(CLI::App& app);
void AddCalibrateCommand(CLI::App& app);
void AddReplayCommand(CLI::App& app);
void AddPlateCommand(CLI::App& app);
void AddBankCommand(CLI::App& app);
void AddBenchCommand(CLI::App& app);
void AddIngestCommand(CLI::App& app);
void AddConfigCommand(CLI::App& app);
void AddAnimateCommand(CLI::App& app);
void AddRenderCommand(CLI::App& app);
void AddJudgeCommand(CLI::App& app);
void AddFakecamCommand(CLI::App& app);
void AddCamerasCommand(CLI::App& app);
void AddSkeletonCommand(CLI::App& app);
void AddMatchCommand(CLI::App& app);
void AddTransitionsCommand(CLI::App& app);
void AddDaemonCommand(CLI::App& app);
void AddImportCommand(CLI::App& app);

}  // namespace ss::apps
