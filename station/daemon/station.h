// The station: config -> recipe, store, drivers, status board, sequencer, HTTP API, and the
// queue of serial numbers waiting to be tested. `eol station` and `eol demo` both run this.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "db/store.h"
#include "drivers/factory/factory.h"
#include "station/daemon/config.h"
#include "station/daemon/health.h"
#include "station/daemon/http_api.h"
#include "station/daemon/plc/plc_server.h"
#include "station/daemon/recipe.h"
#include "station/daemon/recipe_change.h"
#include "station/daemon/sequencer.h"
#include "station/daemon/station_clock.h"
#include "station/daemon/station_metrics.h"
#include "station/daemon/status_board.h"
#include "station/daemon/test_request.h"

namespace eol::station {

class Station {
 public:
  // Loads and validates the recipe (when the configured file does not load, the newest kept
  // version beside it is loaded and tests are refused until a valid recipe is installed;
  // with none, it throws), opens the store (recovering interrupted tests as
  // ABORTED; a damaged, emptied or foreign file throws db::StoreRefused; acknowledged
  // verdicts the store lost are logged and shown, db::Store::loss_on_open), makes the drivers
  // and connects them. A fixture or DAQ that does not answer yet is not fatal: the station
  // says so (a NotReadyCause) and retries while idle (Serve) and at the next test. A bad recipe,
  // config or database is fatal (throws with the cause).
  // With "variants" (station/daemon/variants.h) every variant's recipe must load and be approved:
  // one that does not (a proposal) throws io::ConfigError naming the variant and the file, and two
  // variants of one recipe id are refused; there is no last-good fallback for them.
  // `drivers`: made by the caller (the demo's share one simulated bench with a fixture
  // emulator), both or neither; when empty they are made from the config's "fixture" and "daq"
  // (drivers/factory/factory.h).
  // `clock`: the time it lives by (station/daemon/station_clock.h), handed to the sequencer and
  // read by the idle look and the stuck-test deadline; the real clocks unless a test passes one. A
  // clock whose sleep advances a manual clock needs the drivers' bench on that clock too.
  explicit Station(StationConfig config, drivers::DriverSet drivers = {}, StationClock clock = {});
  ~Station();
  Station(const Station&) = delete;
  Station& operator=(const Station&) = delete;

  // Serves the API; the port actually bound is http_port().
  void StartHttp(const std::string& web_root = "");
  int http_port() const;
  // No cause of not being ready is raised (station/daemon/health.h): the board's not_ready_code
  // and not_ready_reason say which are. While Serve runs, the fixture controller and the DAQ
  // are looked at every health.period_ms when no test runs or waits.
  bool ready() const;

  // Runs one test now, on the calling thread. With variants the serial's rules pick the
  // recipe; a serial they do not pick one for throws std::invalid_argument with the reason
  // (nothing moves, nothing is stored).
  db::TestRecord RunTest(const std::string& serial);

  // For the daemon: queue a serial (one test at a time; refused while one runs or waits).
  bool Enqueue(const std::string& serial, std::string* why);
  // The same for a whole request; `verdicts_before` (optional) gets the number of tests
  // ended before this one was accepted (the PLC's done bit waits for the next). The request's
  // variant is picked here (station/daemon/variants.h SelectVariant; a station of one recipe
  // refuses a request naming another variant or a PLC code): when it is refused, `variant_refusal`
  // (optional) says how and `why` names the serial, the choice and the rules.
  bool Enqueue(const TestRequest& request, std::string* why,
               std::uint64_t* verdicts_before = nullptr, VariantRefusal* variant_refusal = nullptr);
  // Runs queued tests until RequestStop(); returns when the test in flight has ended. Feeds
  // systemd's watchdog from a health thread while it runs (see HealthLoop).
  void Serve();
  // Thread-safe: aborts the test in flight and ends Serve().
  void RequestStop(const std::string& why);

  // The recipe in use: with variants, the last unit's (the first variant's before any).
  std::shared_ptr<const Recipe> recipe() const;
  // GET /api/variants: {"variants": [{"name", "plc_code", "prefixes", "patterns",
  // "recipe": {"id", "version", "hash", "path"}}], "current": name | null}; "variants" is
  // empty on a station of one recipe.
  nlohmann::json VariantsJson() const;
  // PUT /api/recipe: validates a new version of the recipe in use, keeps the old file as
  // <name>.v<old version>.json beside it, replaces the configured file atomically, writes the
  // audit log, and activates it for the next test. Refused while a test runs or waits.
  // Checks run in that order: validation, busy, id, version; then the files, the audit, the
  // swap. Anything refused before the files leaves everything as it was. With variants the
  // new recipe's id picks the variant whose recipe it replaces (one of no variant is refused).
  RecipeChange ChangeRecipe(const nlohmann::json& recipe, const ApiToken& who);
  const StationConfig& config() const { return config_; }
  StatusBoard& board() { return *board_; }
  db::Store& store() { return *store_; }

  // ---- Plant integration (issue 15) ----
  // Serves the line PLC's handshake (station/daemon/plc/plc_server.h) when the config has a "plc"
  // block; the port actually bound is plc_port() (0 when not serving). Throws naming the
  // address when it cannot listen.
  void StartPlc();
  int plc_port() const;
  // Publishes every stored record and the station's status over MQTT
  // (station/daemon/mqtt_publisher.h) when the config has an "mqtt" block.
  void StartMqtt();
  // Replicates every stored record into the plant's central PostgreSQL record
  // (station/daemon/central/central_replicator.h) when the config has a "central" block.
  void StartCentral();

 private:
  StationConfig config_;
  const StationClock clock_;
  mutable std::mutex recipe_mu_;
  std::shared_ptr<const Recipe> recipe_;
  // Non-empty when the configured recipe did not load at start: tests are refused (Enqueue)
  // until ChangeRecipe installs a valid one. Guarded by queue_mu_.
  std::string recipe_problem_;
  // Variants (station/daemon/variants.h): each with its approved recipe and designed excitation;
  // empty on a station of one recipe. Replaced by ChangeRecipe under queue_mu_ while idle.
  struct LoadedVariant {
    VariantConfig config;
    std::shared_ptr<const Recipe> recipe;
    std::shared_ptr<const analysis::Excitation> designed;
  };
  std::vector<LoadedVariant> variants_;
  std::size_t current_variant_ = 0;  // of the last unit (under queue_mu_)
  void LoadVariants();
  // The variant of `request`; false with the reason when refused.
  bool PickVariant(const TestRequest& request, std::size_t* index, std::string* by,
                   std::string* why, VariantRefusal* refusal) const;
  // Before a test of variant `index` (ServeQueue, RunTest): its recipe into the sequencer.
  void UseVariant(std::size_t index, const std::string& by);
  std::unique_ptr<db::Store> store_;
  drivers::DriverSet drivers_;
  std::unique_ptr<StatusBoard> board_;
  std::unique_ptr<Sequencer> sequencer_;
  std::unique_ptr<HttpApi> http_;
  std::unique_ptr<plc::PlcServer> plc_;
  std::unique_ptr<MqttPublisher> mqtt_;
  std::unique_ptr<central::CentralReplicator> central_;
  StationMetrics metrics_;

  mutable std::mutex queue_mu_;
  std::condition_variable queue_cv_;
  struct Queued {
    TestRequest request;
    std::size_t variant = 0;  // with variants: the one picked at Enqueue
    std::string variant_by;
  };
  std::deque<Queued> queue_;
  bool running_test_ = false;
  std::string running_serial_;
  std::chrono::steady_clock::time_point test_started_{};
  double test_deadline_s_ = 0;
  bool stop_ = false;

  void ServeQueue();
  void ConnectDrivers();
  void RestoreBoard();
  // The idle look (station/daemon/health.h); Serve calls it every health.period_ms.
  void LookAtDrivers();
  // Held by a test and by an idle look: never both at once.
  std::mutex fixture_use_mu_;
  std::unique_ptr<FixtureProbe> probe_;
  // After each test: a failed store write makes the station not ready, naming the cause.
  void ShowStoreFailure();
  bool showing_store_failure_ = false;
  // What /metrics reads at scrape time (board, queue, driver and sequencer counters).
  LiveMetrics LiveValues();
  void HealthLoop(const std::atomic<bool>& serving);
  // What the line PLC reads (under queue_mu_): tests ended and records stored since start,
  // and the newest verdict.
  std::uint64_t verdicts_ = 0;
  std::uint64_t stored_ = 0;
  std::optional<analysis::Outcome> last_outcome_;
  std::optional<analysis::ReasonCode> last_reason_;
};

// Seconds after which a test of `recipe` is stuck (Station::HealthLoop).
double TestDeadlineS(const Recipe& recipe, const SafetyOptions& safety);

}  // namespace eol::station
