// The station: config -> recipe, store, drivers, status board, sequencer, HTTP API, and the
// queue of serial numbers waiting to be tested. `eol station` and `eol demo` both run this.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "db/store.h"
#include "drivers/factory/factory.h"
#include "station/config.h"
#include "station/http_api.h"
#include "station/recipe.h"
#include "station/recipe_change.h"
#include "station/sequencer.h"
#include "station/status_board.h"

namespace eol::station {

class Station {
 public:
  // Loads and validates the recipe, opens the store (recovering interrupted tests as
  // ABORTED), makes the drivers and connects them. A fixture or DAQ that does not answer
  // yet is not fatal: the station says so and retries at the next test. A bad recipe,
  // config or database is fatal (throws with the cause).
  // `bench`: a simulated bench shared with a fixture emulator (the demo); normally null.
  explicit Station(StationConfig config, std::shared_ptr<drivers::SimBench> bench = nullptr);
  ~Station();
  Station(const Station&) = delete;
  Station& operator=(const Station&) = delete;

  // Serves the API; the port actually bound is http_port().
  void StartHttp(const std::string& web_root = "");
  int http_port() const;

  // Runs one test now, on the calling thread.
  db::TestRecord RunTest(const std::string& serial);

  // For the daemon: queue a serial (one test at a time; refused while one runs or waits).
  bool Enqueue(const std::string& serial, std::string* why);
  // Runs queued tests until RequestStop(); returns when the test in flight has ended.
  void Serve();
  // Thread-safe: aborts the test in flight and ends Serve().
  void RequestStop(const std::string& why);

  std::shared_ptr<const Recipe> recipe() const;
  // PUT /api/recipe: validates a new version of the recipe in use, keeps the old file as
  // <name>.v<old version>.json beside it, replaces the configured file atomically, writes the
  // audit log, and activates it for the next test. Refused while a test runs or waits.
  // Checks run in that order: validation, busy, id, version; then the files, the audit, the
  // swap. Anything refused before the files leaves everything as it was.
  RecipeChange ChangeRecipe(const nlohmann::json& recipe, const ApiToken& who);
  const StationConfig& config() const { return config_; }
  StatusBoard& board() { return *board_; }
  drivers::SimBench* bench() { return drivers_.bench.get(); }
  db::Store& store() { return *store_; }

 private:
  StationConfig config_;
  mutable std::mutex recipe_mu_;
  std::shared_ptr<const Recipe> recipe_;
  std::unique_ptr<db::Store> store_;
  drivers::DriverSet drivers_;
  std::unique_ptr<StatusBoard> board_;
  std::unique_ptr<Sequencer> sequencer_;
  std::unique_ptr<HttpApi> http_;

  std::mutex queue_mu_;
  std::condition_variable queue_cv_;
  std::deque<std::string> queue_;
  bool running_test_ = false;
  bool stop_ = false;
};

}  // namespace eol::station
