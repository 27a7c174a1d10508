// `eol station --config FILE` and `eol-station --config FILE`: the station as a long-running
// daemon. Serials arrive over HTTP (POST /api/tests), from the line PLC (a "plc" block:
// station/daemon/plc/plc_map.h) or, with "serial_from_stdin", from a scanner typing into stdin.
// SIGTERM/SIGINT abort the test in flight safely (excitation off, safe state, stored as
// ABORTED) and stop the daemon.
#include "station/cli/station_command.h"

#include <signal.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <memory>
#include <thread>

#include "db/serial_number.h"
#include "drivers/io/json_config.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/data_files.h"
#include "station/daemon/station.h"
#include "station/daemon/systemd_notify.h"
#include "station/daemon/test_request.h"

namespace eol::station::cli {
namespace {

constexpr int kExitConfigError = 78;  // EX_CONFIG (sysexits.h)
// The store is damaged, emptied or not a store (db::StoreRefused): restarting cannot fix it
// either; the unit's RestartPreventExitStatus names this code too.
constexpr int kExitStoreRefused = 65;  // EX_DATAERR (sysexits.h)

int RunStation(const std::string& config_path, std::string web_root, bool init_store) {
  // Block the stop signals in every thread; one thread waits for them with sigwait.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  std::unique_ptr<Station> made;
  try {
    StationConfig config = LoadStationConfig(config_path);
    config.init_store = config.init_store || init_store;
    made = std::make_unique<Station>(std::move(config));
  } catch (const io::ConfigError& e) {
    // Restarting cannot fix a file: the unit's RestartPreventExitStatus names this code.
    std::cerr << "eol station: configuration error: " << e.what() << " (exit " << kExitConfigError
              << ": fix the file, then start the station again)" << std::endl;
    return kExitConfigError;
  } catch (const db::StoreRefused& e) {
    std::cerr << "eol station: store refused: " << e.what() << " (exit " << kExitStoreRefused
              << ": the station does not start on this file)" << std::endl;
    return kExitStoreRefused;
  }
  Station& station = *made;
  if (web_root.empty()) web_root = DefaultWebRoot();
  station.StartHttp(web_root);
  station.StartPlc();      // when the config has a "plc" block
  station.StartMqtt();     // when the config has an "mqtt" block
  station.StartCentral();  // when the config has a "central" block
  // "ready" only when the fixture and the DAQ answered; otherwise the daemon is up (the API
  // answers, each test retries the drivers) and says what is missing.
  const nlohmann::json board = station.board().Snapshot();
  const std::string readiness =
      station.ready() ? "ready" : "up, NOT READY (" + board.value("not_ready_reason", "") + ")";
  const std::string simulation = board.value("simulation", "");
  std::cout << "eol station: " << station.config().station_id << " " << readiness << ", recipe "
            << station.recipe()->id << " v" << station.recipe()->version << ", http://"
            << station.config().http_listen << ":" << station.http_port() << "/";
  const nlohmann::json variants = station.VariantsJson()["variants"];  // empty: one recipe
  for (const auto& v : variants)
    std::cout << ", variant " << v["name"].get<std::string>() << " = "
              << v["recipe"]["id"].get<std::string>() << " v" << v["recipe"]["version"].get<int>();
  if (station.config().plc)
    std::cout << ", plc modbus://" << station.config().plc->listen << ":" << station.plc_port();
  std::cout << (simulation.empty() ? "" : ", SIMULATION (" + simulation + ")") << std::endl;

  NotifyReady((station.ready() ? "testing " : "NOT READY, testing ") + station.recipe()->id + " v" +
              std::to_string(station.recipe()->version) +
              (simulation.empty() ? "" : " in SIMULATION"));
  std::thread signal_thread([&] {
    int sig = 0;
    sigwait(&stop_signals, &sig);
    spdlog::warn("received {}: stopping (test in flight is aborted safely)",
                 sig == SIGTERM ? "SIGTERM" : "SIGINT");
    NotifyStopping();
    station.RequestStop(sig == SIGTERM ? "station stopping (SIGTERM)"
                                       : "station stopping (SIGINT)");
  });
  if (station.config().serial_from_stdin) {
    std::thread([&station] {
      std::string line;
      while (std::getline(std::cin, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        // The scanner's line: the serial, then TAB-separated key=value fields
        // (station/daemon/test_request.h).
        std::string why;
        const std::optional<TestRequest> request = ParseScannerLine(line, &why);
        if (!request || !station.Enqueue(*request, &why))
          spdlog::warn("scanner line '{}' refused: {}", line, why);
      }
    }).detach();
  }
  station.Serve();
  // Serve() only returns after RequestStop(), i.e. after the signal thread ran.
  signal_thread.join();
  std::cout << "eol station: stopped" << std::endl;
  return 0;
}

}  // namespace

const char* const kStationDescription =
    "Run the station as a daemon with the JSON config FILE (see deploy/station.json): serve\n"
    "the HTTP API and operator page, test each serial that arrives, stop cleanly on SIGTERM.";

void AddStationOptions(CLI::App& cmd) {
  auto config = std::make_shared<std::string>();
  auto web_root = std::make_shared<std::string>();
  auto init_store = std::make_shared<bool>(false);
  cmd.add_option("--config", *config, "Station config JSON")->required()->check(CLI::ExistingFile);
  cmd.add_option("--web-root", *web_root, "Folder of the operator page (default: built in)");
  cmd.add_flag("--init-store", *init_store,
               "Make an existing empty file (0 bytes, or an SQLite file without tables) at the "
               "config's \"db\" a new store; without it such a file is refused (a missing "
               "file is always created)");
  cmd.callback([config, web_root, init_store] {
    RunGuarded("station", [&] { return RunStation(*config, *web_root, *init_store); });
  });
}

void AddStationCommand(CLI::App& app) {
  AddStationOptions(*app.add_subcommand("station", kStationDescription));
}

}  // namespace eol::station::cli
