// The `eol` subcommands. Each Add*Command registers one subcommand on the app with its
// options and a callback; main.cc lists them all in one place. A callback reports failure
// by throwing CLI::RuntimeError(exit_code) after printing the reason to stderr.
#pragma once

#include <CLI/CLI.hpp>

namespace eol::station::cli {

void AddDemoCommand(CLI::App& app);
void AddStationCommand(CLI::App& app);
void AddFixtureSimCommand(CLI::App& app);
void AddAnalyzeCommand(CLI::App& app);
void AddSimulateCommand(CLI::App& app);
void AddFitBenchCommand(CLI::App& app);
void AddGapCommand(CLI::App& app);
void AddGapBenchCommand(CLI::App& app);
void AddQueryCommand(CLI::App& app);
void AddExportCommand(CLI::App& app);
void AddSafetyBenchCommand(CLI::App& app);
void AddStatsCommand(CLI::App& app);
void AddCalibrateCommand(CLI::App& app);
void AddTeachCommand(CLI::App& app);
void AddDetectabilityCommand(CLI::App& app);
void AddProductionBenchCommand(CLI::App& app);
void AddHttpBenchCommand(CLI::App& app);
void AddCycleBenchCommand(CLI::App& app);
void AddPodCommand(CLI::App& app);
void AddRecipeApproveCommand(CLI::App& app);
void AddPlantBenchCommand(CLI::App& app);
void AddDesignExcitationCommand(CLI::App& app);
void AddRecipeNewCommand(CLI::App& app);
void AddDbBenchCommand(CLI::App& app);
void AddTeardownCommand(CLI::App& app);
void AddReportCommand(CLI::App& app);

}  // namespace eol::station::cli
