#include "station/daemon/station.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include "analysis/text.h"
#include "db/clock.h"
#include "drivers/fixture/modbus_tcp_server.h"
#include "station/daemon/systemd_notify.h"
#include "station/daemon/version.h"

namespace eol::station {

namespace {

// The configured recipe; when it does not load, the newest kept version beside it that does
// (<stem>.v<N>.json, kept by ChangeRecipe), with `problem` saying so. Throws the configured
// file's ConfigError when no kept version loads either.
Recipe LoadRecipeOrLastGood(const std::string& path, std::string* problem) {
  namespace fs = std::filesystem;
  try {
    return LoadRecipe(path);
  } catch (const io::ConfigError& e) {
    const fs::path p(path);
    const std::string prefix = p.stem().string() + ".v";
    std::optional<std::pair<int, fs::path>> newest;
    std::error_code ec;
    for (const auto& entry :
         fs::directory_iterator(p.parent_path().empty() ? "." : p.parent_path(), ec)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind(prefix, 0) != 0 || entry.path().extension() != ".json") continue;
      const std::string digits = name.substr(prefix.size(), name.size() - prefix.size() - 5);
      if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) continue;
      const int v = std::stoi(digits);
      if (!newest || v > newest->first) newest = {v, entry.path()};
    }
    if (!newest) throw;
    Recipe last = LoadRecipe(newest->second.string());
    *problem = std::string(e.what()) + "; tests are refused until a valid recipe is installed " +
               "(PUT /api/recipe or a fixed file and a restart); the last good version v" +
               std::to_string(last.version) + " (" + newest->second.string() + ") is shown";
    return last;
  }
}

}  // namespace

Station::Station(StationConfig config, drivers::DriverSet drivers, StationClock clock)
    : config_(std::move(config)), clock_(std::move(clock)) {
  if (!drivers.fixture != !drivers.daq)
    throw std::invalid_argument("Station: a fixture and a DAQ, or neither");
  if (config_.variants.empty()) {
    recipe_ =
        std::make_shared<const Recipe>(LoadRecipeOrLastGood(config_.recipe_path, &recipe_problem_));
    if (recipe_problem_.empty() && !recipe_->Approved())
      recipe_problem_ = recipe_->WhyNotApproved() + "; tests are refused until then";
  } else {
    LoadVariants();
  }
  if (!recipe_problem_.empty()) spdlog::error("{}", recipe_problem_);
  spdlog::info("recipe {} v{} ({}), sha256 {}", recipe_->id, recipe_->version, config_.recipe_path,
               recipe_->hash.substr(0, 12));
  db::OpenOptions store_options;
  store_options.create_if_empty = config_.init_store;
  store_ = db::Store::Open(config_.db_path, db::Store::Role::kWriter, store_options);
  if (store_->aborted_on_open() > 0)
    spdlog::warn("store {}: {} test(s) interrupted by a previous stop recorded as ABORTED",
                 config_.db_path, store_->aborted_on_open());
  if (!store_->check_on_open().empty())
    spdlog::warn("store {}: {}", config_.db_path, store_->check_on_open());
  if (!store_->loss_on_open().empty())
    spdlog::error("store {}: VERDICTS LOST: {}", config_.db_path, store_->loss_on_open());
  drivers_ = drivers.fixture ? std::move(drivers) : drivers::MakeDrivers(config_.drivers);
  board_ = std::make_unique<StatusBoard>(config_.station_id, recipe_->id, recipe_->hash);
  ConnectDrivers();
  if (!recipe_problem_.empty()) {
    board_->SetMessage(recipe_problem_);
    board_->SetCause(NotReadyCause::kRecipeInvalid, recipe_problem_);
  }
  if (!store_->loss_on_open().empty()) {
    // Named until the first test; the journal keeps it. Tests go on: refusing them would not
    // bring the lost records back, and new tests get ids of their own.
    const std::string lost = "store lost acknowledged verdicts: " + store_->loss_on_open();
    board_->SetMessage(lost);
    board_->SetCause(NotReadyCause::kStoreLostVerdicts, lost);
  }
  RestoreBoard();
  probe_ = std::make_unique<FixtureProbe>(
      *drivers_.fixture,
      std::chrono::milliseconds(std::lround(config_.safety.heartbeat_timeout_ms)));
  const std::string simulation = SimulationReason(config_);
  if (!simulation.empty()) {
    spdlog::warn("SIMULATION ({}): records are marked and are no production results", simulation);
    board_->SetSimulation(simulation);
  }
  SequencerOptions opts;
  opts.station_id = config_.station_id;
  opts.simulation = simulation;
  opts.safety = config_.safety;
  opts.self_check = config_.self_check;
  opts.publish_before_release = config_.publish_before_release;
  opts.clock = clock_;
  opts.on_serial = drivers_.on_serial;
  sequencer_ = std::make_unique<Sequencer>(*drivers_.fixture, *drivers_.daq, *store_, recipe_,
                                           *board_, opts);
  sequencer_->PublishLockout();  // a lockout survives a restart: it is read from the store
}

// Every variant's recipe loaded, approved and its excitation designed, or the station does not
// start: a proposal or a broken file is named with its variant.
void Station::LoadVariants() {
  for (const VariantConfig& v : config_.variants) {
    const std::string where = "variant '" + v.name + "' (" + v.recipe_path + "): ";
    std::shared_ptr<const Recipe> r;
    try {
      r = std::make_shared<const Recipe>(LoadRecipe(v.recipe_path));
    } catch (const io::ConfigError& e) {
      throw io::ConfigError(where + e.what());
    }
    if (!r->Approved())
      throw io::ConfigError(where + r->WhyNotApproved() + "; the station does not start with it");
    for (const LoadedVariant& other : variants_)
      if (other.recipe->id == r->id)
        throw io::ConfigError(where + "recipe id '" + r->id + "' is already variant '" +
                              other.config.name + "''s: one variant per recipe");
    std::shared_ptr<const analysis::Excitation> designed;
    try {
      designed =
          std::make_shared<const analysis::Excitation>(analysis::DesignMultisine(r->excitation));
    } catch (const std::exception& e) {
      throw io::ConfigError(where + "/excitation: cannot be designed: " + e.what());
    }
    spdlog::info("variant {}: recipe {} v{} ({}), sha256 {}", v.name, r->id, r->version,
                 v.recipe_path, r->hash.substr(0, 12));
    variants_.push_back({v, std::move(r), std::move(designed)});
  }
  recipe_ = variants_.front().recipe;
}

bool Station::PickVariant(const TestRequest& request, std::size_t* index, std::string* by,
                          std::string* why, VariantRefusal* refusal) const {
  VariantSelection s;
  if (variants_.empty()) {  // one recipe: nothing to pick, and no other variant to name
    const std::string id = recipe()->id;
    if (!request.variant.name.empty() && request.variant.name != id)
      s = {VariantRefusal::kUnknown, 0, "",
           "unknown variant '" + request.variant.name + "': this station runs one recipe (" + id +
               ") and no variants"};
    else if (request.variant.plc_code != 0)
      s = {VariantRefusal::kUnknown, 0, "",
           "the PLC's variant register holds " + std::to_string(request.variant.plc_code) +
               ": this station runs one recipe (" + id + ") and no variants; write 0"};
  } else {
    s = SelectVariant(config_.variants, request.serial, request.variant);
  }
  if (refusal != nullptr) *refusal = s.refusal;
  if (s.refusal != VariantRefusal::kNone) {
    *why = s.why;
    return false;
  }
  *index = s.index;
  *by = s.by;
  return true;
}

void Station::UseVariant(std::size_t index, const std::string& by) {
  if (variants_.empty()) return;
  std::shared_ptr<const Recipe> r;
  std::shared_ptr<const analysis::Excitation> designed;
  {
    std::lock_guard<std::mutex> lock(queue_mu_);  // ChangeRecipe replaces them under it
    r = variants_[index].recipe;
    designed = variants_[index].designed;
    current_variant_ = index;
  }
  sequencer_->SetRecipe(r, *designed);
  sequencer_->SetVariant(variants_[index].config.name, by);
  bool changed = false;
  {
    std::lock_guard<std::mutex> lock(recipe_mu_);
    changed = recipe_ != r;
    recipe_ = r;
  }
  if (changed) board_->SetRecipe(r->id, r->hash);
}

nlohmann::json Station::VariantsJson() const {
  nlohmann::json list = eol::station::VariantsJson(config_.variants);
  std::lock_guard<std::mutex> lock(queue_mu_);
  for (std::size_t i = 0; i < variants_.size(); ++i) {
    const Recipe& r = *variants_[i].recipe;
    list[i]["recipe"] = {{"id", r.id},
                         {"version", r.version},
                         {"hash", r.hash},
                         {"path", variants_[i].config.recipe_path}};
  }
  return {{"variants", list},
          {"current", variants_.empty() ? nlohmann::json()
                                        : nlohmann::json(variants_[current_variant_].config.name)}};
}

// A fixture or DAQ that does not answer yet is not fatal: the idle look (LookAtDrivers)
// and each test retry it.
void Station::ConnectDrivers() {
  if (const drivers::Status s = drivers_.fixture->Connect(); !s.ok()) {
    spdlog::error("{} (retried while idle and at the next test)", s.message());
    board_->SetCause(NotReadyCause::kFixtureUnreachable, "fixture unavailable: " + s.message());
  }
  if (const drivers::Status s = drivers_.daq->Connect(); !s.ok()) {
    spdlog::error("{} (retried while idle and at the next test)", s.message());
    board_->SetCause(NotReadyCause::kAcquisitionUnavailable,
                     "acquisition unavailable: " + s.message());
  }
  board_->ClearCause(NotReadyCause::kDriversNotConnected);  // tried: their own causes stand
}

// Shift continuity: "Last results" and the day's counts as the store holds them,
// so that a restart shows what the shift did so far.
void Station::RestoreBoard() {
  const auto now = clock_.wall();
  db::TestQuery day;
  day.from = db::UtcIso8601(LocalMidnight(now));
  day.limit = 1000;
  VerdictCounts counts;
  for (std::vector<db::TestRecord> page = store_->Tests(day); !page.empty();
       page = store_->Tests(day)) {
    for (const db::TestRecord& r : page) counts.Add(r.outcome);
    day.after = {page.back().started_at, page.back().id};
  }
  db::TestQuery recent;
  recent.limit = 20;
  board_->Restore(store_->Tests(recent), counts, LocalDay(now));
}

Station::~Station() {
  if (plc_) plc_->Stop();
  if (mqtt_) mqtt_->Stop();
  if (central_) central_->Stop();
  if (http_) http_->Stop();
  if (drivers_.fixture) drivers_.fixture->Disconnect();
  if (drivers_.daq) drivers_.daq->Disconnect();
}

void Station::StartHttp(const std::string& web_root) {
  // Many HTTP connections must never push the fixture link's descriptor past select()'s range.
  drivers::KeepDescriptorsBelowFdSetSize();
  HttpOptions o;
  o.listen = config_.http_listen;
  o.port = config_.http_port;
  o.db_path = config_.db_path;
  o.tokens = config_.tokens;
  o.hosts = config_.http_hosts;
  o.web_root = web_root;
  o.language = config_.language;
  if (config_.central) o.central_postgres = config_.central->postgres;
  HttpHandlers h;
  h.start_test = [this](const TestRequest& r, std::string* why, VariantRefusal* refusal) {
    return Enqueue(r, why, nullptr, refusal);
  };
  h.variants = [this] { return VariantsJson(); };
  h.recipe = [this] {
    const auto r = recipe();
    nlohmann::json j = r->source;
    j["hash"] = r->hash;
    j["instructions"] = InstructionsJson(r->instructions);  // defaults written out
    return j;
  };
  h.current_recipe = [this] { return recipe(); };
  h.change_recipe = [this](const nlohmann::json& j, const ApiToken& who) {
    return ChangeRecipe(j, who);
  };
  h.metrics = [this] { return metrics_.Render(LiveValues()); };
  http_ = std::make_unique<HttpApi>(*board_, o, h);
  http_->Start();
}

std::shared_ptr<const Recipe> Station::recipe() const {
  std::lock_guard<std::mutex> lock(recipe_mu_);
  return recipe_;
}

RecipeChange Station::ChangeRecipe(const nlohmann::json& j, const ApiToken& who) {
  auto refused = [](RecipeChange::Kind kind, std::string message) {
    RecipeChange r;
    r.kind = kind;
    r.message = std::move(message);
    return r;
  };
  std::shared_ptr<const Recipe> next;
  try {
    next = std::make_shared<const Recipe>(ParseRecipe(j, "PUT /api/recipe"));
  } catch (const io::ConfigError& e) {
    return refused(RecipeChange::Kind::kInvalid, e.what());
  }
  if (!next->Approved())
    return refused(RecipeChange::Kind::kNotApproved, "PUT /api/recipe: " + next->WhyNotApproved());
  // Everything the new recipe needs is built before anything is renamed, audited or swapped:
  // a recipe whose excitation cannot be designed leaves the station as it was.
  analysis::Excitation designed;
  try {
    designed = analysis::DesignMultisine(next->excitation);
  } catch (const std::exception& e) {
    return refused(RecipeChange::Kind::kInvalid,
                   std::string("PUT /api/recipe: /excitation: cannot be designed: ") + e.what());
  }
  // Holding the queue lock keeps the sequencer idle until the new recipe is in place.
  std::lock_guard<std::mutex> queue_lock(queue_mu_);
  if (running_test_ || !queue_.empty())
    return refused(RecipeChange::Kind::kBusy,
                   "a test is running or waiting; change the recipe between tests");
  std::shared_ptr<const Recipe> current = recipe();
  namespace fs = std::filesystem;
  fs::path path = config_.recipe_path;
  std::optional<std::size_t> variant;  // with variants: the one whose recipe is replaced
  for (std::size_t i = 0; i < variants_.size(); ++i)
    if (variants_[i].recipe->id == next->id) variant = i;
  if (variant) {
    current = variants_[*variant].recipe;
    path = variants_[*variant].config.recipe_path;
  } else if (!variants_.empty()) {
    std::string ids;
    for (const LoadedVariant& v : variants_)
      ids += (ids.empty() ? "" : ", ") + v.config.name + ": " + v.recipe->id;
    return refused(RecipeChange::Kind::kWrongRecipe,
                   "recipe id '" + next->id + "' is none of this station's variants' (" + ids +
                       "); a new variant needs a new station config");
  }
  if (next->id != current->id)
    return refused(RecipeChange::Kind::kWrongRecipe,
                   "recipe id must stay '" + current->id +
                       "' (another motor type needs another station config)");
  if (next->version <= current->version)
    return refused(RecipeChange::Kind::kVersionNotIncreased,
                   "version must increase: the station runs version " +
                       std::to_string(current->version) + ", got " + std::to_string(next->version));
  const fs::path kept = path.parent_path() /
                        (path.stem().string() + ".v" + std::to_string(current->version) + ".json");
  try {
    if (!fs::exists(kept)) fs::copy_file(path, kept);
    WriteRecipeFile(path.string(), j);
  } catch (const std::exception& e) {
    return refused(RecipeChange::Kind::kIoError, e.what());
  }
  db::RecipeAudit audit;
  audit.at = db::UtcNowIso8601();
  audit.who = who.name;
  audit.role = ToString(who.role);
  audit.recipe_id = next->id;
  audit.old_version = current->version;
  audit.new_version = next->version;
  audit.old_hash = current->hash;
  audit.new_hash = next->hash;
  audit.path = path.string();
  store_->AppendAudit(audit);
  if (variant) {  // under queue_mu_: the next test of this variant takes it (UseVariant)
    variants_[*variant].recipe = next;
    variants_[*variant].designed = std::make_shared<const analysis::Excitation>(designed);
  }
  const bool in_use = recipe()->id == next->id;  // with variants: the last unit's recipe
  if (in_use) {
    std::lock_guard<std::mutex> lock(recipe_mu_);
    recipe_ = next;
  }
  if (!recipe_problem_.empty()) {  // under queue_mu_, as Enqueue reads it
    recipe_problem_.clear();
    board_->SetMessage("");
    // Only the recipe's cause: a fixture that never answered keeps its own.
    board_->ClearCause(NotReadyCause::kRecipeInvalid);
  }
  if (in_use) {
    sequencer_->SetRecipe(next, std::move(designed));
    board_->SetRecipe(next->id, next->hash);
  }
  spdlog::warn("recipe {} changed by {} ({}): v{} {} -> v{} {}", next->id, who.name,
               ToString(who.role), current->version, current->hash.substr(0, 12), next->version,
               next->hash.substr(0, 12));
  RecipeChange changed;
  changed.kind = RecipeChange::Kind::kChanged;
  changed.id = next->id;
  changed.version = next->version;
  changed.hash = next->hash;
  changed.path = path.string();
  changed.previous_version = current->version;
  changed.previous_hash = current->hash;
  changed.kept_as = kept.string();
  return changed;
}

bool Station::ready() const { return board_->Snapshot().value("ready", false); }

int Station::http_port() const { return http_ ? http_->port() : 0; }

db::TestRecord Station::RunTest(const std::string& serial) {
  std::size_t variant = 0;
  std::string by, why;
  if (!PickVariant(TestRequest{serial, {}, {}}, &variant, &by, &why, nullptr))
    throw std::invalid_argument(why);
  db::TestRecord r;
  {
    std::lock_guard<std::mutex> fixture_lock(fixture_use_mu_);
    UseVariant(variant, by);
    r = sequencer_->RunTest(serial);
  }
  metrics_.OnTest(r);
  ShowStoreFailure();
  return r;
}

// A write that failed (a full disk): the station is not ready, and says why, until a write
// succeeds (the next test's BeginTest first finishes the failed test as ERROR). Lost verdicts
// found at start are named until this first test after them.
void Station::ShowStoreFailure() {
  board_->ClearCause(NotReadyCause::kStoreLostVerdicts);
  const std::string& failure = store_->write_failure();
  if (failure.empty()) {
    if (showing_store_failure_) board_->SetMessage("");
    showing_store_failure_ = false;
    board_->ClearCause(NotReadyCause::kStoreWriteFailed);
    return;
  }
  showing_store_failure_ = true;
  spdlog::error("store write failed, station not ready: {}", failure);
  board_->SetMessage("store write failed: " + failure);
  board_->SetCause(NotReadyCause::kStoreWriteFailed, "store write failed: " + failure);
}

// One idle look at the drivers (station/daemon/health.h), every health.period_ms while Serve runs:
// skipped while a test runs or waits, and a test waits for a look in flight.
void Station::LookAtDrivers() {
  {
    std::lock_guard<std::mutex> lock(queue_mu_);
    if (running_test_ || !queue_.empty() || stop_) return;
  }
  std::unique_lock<std::mutex> fixture_lock(fixture_use_mu_, std::try_to_lock);
  if (!fixture_lock.owns_lock()) return;
  const std::vector<FixtureProbe::Finding> found = probe_->Look(clock_.now());
  for (NotReadyCause cause : kFixtureCauses) {
    const auto it = std::find_if(found.begin(), found.end(),
                                 [cause](const auto& f) { return f.first == cause; });
    if (it == found.end()) {
      if (board_->HasCause(cause)) spdlog::info("{} cleared while idle", Code(cause));
      board_->ClearCause(cause);
    } else {
      if (!board_->HasCause(cause)) spdlog::error("not ready: {} while idle", it->second);
      board_->SetCause(cause, it->second);
    }
  }
  if (drivers_.daq->lifecycle() == drivers::Lifecycle::kInactive) return;
  if (const drivers::Status s = drivers_.daq->Connect(); !s.ok())
    board_->SetCause(NotReadyCause::kAcquisitionUnavailable,
                     "acquisition unavailable: " + s.message());
  else
    board_->ClearCause(NotReadyCause::kAcquisitionUnavailable);
}

LiveMetrics Station::LiveValues() {
  LiveMetrics m;
  const nlohmann::json board = board_->Snapshot();
  const std::string state = board.value("state", "");
  m.testing = state != "wait_serial" && state != "idle";
  m.ready = board.value("ready", false);
  m.locked_out = board["lockout"].is_object() && board["lockout"].value("locked", false);
  m.simulation = !board.value("simulation", std::string()).empty();
  {
    std::lock_guard<std::mutex> lock(queue_mu_);
    m.queue_length = queue_.size();
  }
  m.fixture_errors = drivers_.fixture->failures();
  m.watchdog_trips = sequencer_->watchdog_trips();
  m.db_path = config_.db_path;
  m.station_id = config_.station_id;
  const auto r = recipe();
  m.recipe_id = r->id;
  m.recipe_hash = r->hash;
  m.software_version = SoftwareVersion();
  if (central_) {
    const central::CentralStatus c = central_->status();
    m.central_connected = c.connected;
    if (c.backlog >= 0) m.central_backlog = c.backlog;
  }
  return m;
}

bool Station::Enqueue(const std::string& serial, std::string* why) {
  return Enqueue(TestRequest{serial, {}, {}}, why);
}

bool Station::Enqueue(const TestRequest& request, std::string* why, std::uint64_t* verdicts_before,
                      VariantRefusal* variant_refusal) {
  if (variant_refusal != nullptr) *variant_refusal = VariantRefusal::kNone;
  std::lock_guard<std::mutex> lock(queue_mu_);
  if (stop_) {
    *why = "station is stopping";
    return false;
  }
  if (!recipe_problem_.empty()) {
    *why = recipe_problem_;
    return false;
  }
  Queued queued{request, 0, ""};
  if (!PickVariant(request, &queued.variant, &queued.variant_by, why, variant_refusal)) {
    spdlog::warn("start of serial '{}' refused: {}", request.serial, *why);
    return false;
  }
  if (running_test_ || !queue_.empty()) {
    *why = "busy: a test is running or waiting";
    return false;
  }
  queue_.push_back(std::move(queued));
  if (verdicts_before != nullptr) *verdicts_before = verdicts_;
  queue_cv_.notify_all();
  return true;
}

// A deadline no healthy test reaches: the excitation of every phase pair, the clamp and
// release timeouts, the safe state's retries, and a generous allowance for analysis and I/O.
double TestDeadlineS(const Recipe& r, const SafetyOptions& safety) {
  const double excite_s =
      static_cast<double>(r.transient_periods + r.periods) / r.excitation.line_spacing_hz;
  const double per_pair_s = excite_s + 10.0;
  return static_cast<double>(r.phase_pairs.size()) * per_pair_s + r.clamp_timeout_s +
         r.release_timeout_s + safety.safe_state_retry_s + 30.0;
}

void Station::Serve() {
  std::atomic<bool> serving{true};
  std::thread health([&] { HealthLoop(serving); });
  {
    const PeriodicTask looks(std::chrono::milliseconds(std::lround(config_.health.period_ms)),
                             [this] { LookAtDrivers(); });
    ServeQueue();
  }
  serving = false;
  health.join();
}

// systemd's watchdog is fed from the daemon's health, not from the serial loop: the station
// is healthy while it waits for a serial, and while the test in flight is within its own
// deadline (TestDeadlineS). A test past its deadline is stuck: excitation off, the operator
// told, and the pings stop so systemd restarts the daemon (the store records the test as
// ABORTED when it reopens).
void Station::HealthLoop(const std::atomic<bool>& serving) {
  bool reported = false;
  while (serving) {
    std::string stuck;
    {
      std::lock_guard<std::mutex> lock(queue_mu_);
      if (running_test_) {
        const double running_s =
            std::chrono::duration<double>(clock_.now() - test_started_).count();
        if (running_s > test_deadline_s_)
          stuck = "test of " + running_serial_ + " running for " + analysis::Fixed(running_s, 0) +
                  " s, beyond its deadline of " + analysis::Fixed(test_deadline_s_, 0) + " s";
      }
    }
    if (stuck.empty()) {
      NotifyWatchdog();
      reported = false;
    } else if (!reported) {
      (void)drivers_.fixture->Write(drivers::FixtureOutput::kExcitationEnable, false);
      spdlog::error("{}: excitation off, watchdog pings stopped (systemd restarts the daemon)",
                    stuck);
      board_->SetMessage(stuck + "; call maintenance");
      metrics_.OnStuckTest();
      reported = true;
    }
    for (int i = 0; i < 10 && serving; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

void Station::ServeQueue() {
  while (true) {
    Queued queued;
    {
      std::unique_lock<std::mutex> lock(queue_mu_);
      int idle_s = 0;
      while (!queue_cv_.wait_for(lock, std::chrono::seconds(1),
                                 [&] { return stop_ || !queue_.empty(); })) {
        if (++idle_s % 60 == 0) sequencer_->PublishLockout();  // a check falls due with time
      }
      if (stop_) return;
      queued = queue_.front();
      queue_.pop_front();
      running_test_ = true;
      running_serial_ = queued.request.serial;
      test_started_ = clock_.now();
      test_deadline_s_ = TestDeadlineS(
          variants_.empty() ? *recipe() : *variants_[queued.variant].recipe, config_.safety);
    }
    const TestRequest& request = queued.request;
    db::TestRecord r;
    {
      std::lock_guard<std::mutex> fixture_lock(fixture_use_mu_);  // no idle look meanwhile
      UseVariant(queued.variant, queued.variant_by);
      r = sequencer_->RunTest(request.serial, request.work);
    }
    metrics_.OnTest(r);
    ShowStoreFailure();
    spdlog::info("[{}] {} {}", r.serial, analysis::ToString(r.outcome),
                 r.reasons.empty() ? "" : r.reasons.front().text);
    std::lock_guard<std::mutex> lock(queue_mu_);
    // Plant integration: what the line PLC reads, changed together with running_test_.
    ++verdicts_;
    if (r.id != 0) ++stored_;  // refusals by the sequencer (lockout, ...) store nothing
    last_outcome_ = r.outcome;
    last_reason_.reset();
    if (!r.reasons.empty()) last_reason_ = r.reasons.front().code;
    running_test_ = false;
  }
}

void Station::RequestStop(const std::string& why) {
  {
    std::lock_guard<std::mutex> lock(queue_mu_);
    stop_ = true;
    queue_.clear();
    queue_cv_.notify_all();
  }
  sequencer_->RequestAbort(why);
}

// ---- Plant integration (issue 15) ----

void Station::StartPlc() {
  if (!config_.plc || plc_) return;
  plc::PlcBackend backend;
  backend.start = [this](const TestRequest& request) {
    plc::PlcStartReply reply;
    VariantRefusal variant = VariantRefusal::kNone;
    if (Enqueue(request, &reply.message, &reply.verdicts_before, &variant)) return reply;
    std::lock_guard<std::mutex> lock(queue_mu_);
    reply.refusal = stop_                                  ? plc::PlcRefusal::kStopping
                    : variant == VariantRefusal::kUnknown  ? plc::PlcRefusal::kUnknownVariant
                    : variant == VariantRefusal::kNoRule   ? plc::PlcRefusal::kNoVariant
                    : variant == VariantRefusal::kConflict ? plc::PlcRefusal::kVariantConflict
                                                           : plc::PlcRefusal::kBusy;
    return reply;
  };
  backend.view = [this] {
    plc::PlcStationView v;
    {
      std::lock_guard<std::mutex> lock(queue_mu_);
      v.busy = running_test_ || !queue_.empty();
      v.stopping = stop_;
      v.verdicts = verdicts_;
      v.stored = stored_;
      v.last_outcome = last_outcome_;
      v.last_reason = last_reason_;
    }
    const nlohmann::json lockout = board_->Snapshot()["lockout"];
    v.lockout = lockout.is_object() && lockout.value("locked", false);
    return v;
  };
  plc_ = std::make_unique<plc::PlcServer>(*config_.plc, std::move(backend));
  plc_->Start();
}

int Station::plc_port() const { return plc_ ? plc_->port() : 0; }

void Station::StartMqtt() {
  if (!config_.mqtt || mqtt_) return;
  mqtt_ = std::make_unique<MqttPublisher>(
      *config_.mqtt, config_.station_id, config_.db_path,
      [this] { return board_->Snapshot()["state"].get<std::string>(); });
  mqtt_->Start();
}

void Station::StartCentral() {
  if (!config_.central || central_) return;
  central_ = std::make_unique<central::CentralReplicator>(*config_.central, config_.db_path,
                                                          config_.station_id);
  central_->Start();
}

}  // namespace eol::station
