#include "station/station.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>

#include "db/clock.h"
#include "station/systemd_notify.h"

namespace eol::station {

Station::Station(StationConfig config, std::shared_ptr<drivers::SimBench> bench)
    : config_(std::move(config)) {
  recipe_ = std::make_shared<const Recipe>(LoadRecipe(config_.recipe_path));
  spdlog::info("recipe {} v{} ({}), sha256 {}", recipe_->id, recipe_->version, config_.recipe_path,
               recipe_->hash.substr(0, 12));
  store_ = db::Store::Open(config_.db_path);
  if (store_->aborted_on_open() > 0)
    spdlog::warn("store {}: {} test(s) interrupted by a previous stop recorded as ABORTED",
                 config_.db_path, store_->aborted_on_open());
  drivers_ = drivers::MakeDrivers(config_.drivers, std::move(bench));
  board_ = std::make_unique<StatusBoard>(config_.station_id, recipe_->id, recipe_->hash);
  if (const drivers::Status s = drivers_.fixture->Connect(); !s.ok()) {
    spdlog::error("{} (will retry at the next test)", s.message());
    board_->SetMessage(s.message());
  }
  if (const drivers::Status s = drivers_.daq->Connect(); !s.ok()) {
    spdlog::error("{} (will retry at the next test)", s.message());
    board_->SetMessage(s.message());
  }
  SequencerOptions opts;
  opts.station_id = config_.station_id;
  opts.safety = config_.safety;
  opts.self_check = config_.self_check;
  if (drivers_.bench && drivers_.bench->settings().load_part_on_serial) {
    drivers::SimBench* bench = drivers_.bench.get();
    opts.on_serial = [bench](const std::string& serial) { bench->LoadPart(serial); };
  }
  sequencer_ = std::make_unique<Sequencer>(*drivers_.fixture, *drivers_.daq, *store_, recipe_,
                                           *board_, opts);
  sequencer_->PublishLockout();  // a lockout survives a restart: it is read from the store
}

Station::~Station() {
  if (http_) http_->Stop();
  if (drivers_.fixture) drivers_.fixture->Disconnect();
  if (drivers_.daq) drivers_.daq->Disconnect();
}

void Station::StartHttp(const std::string& web_root) {
  HttpOptions o;
  o.listen = config_.http_listen;
  o.port = config_.http_port;
  o.db_path = config_.db_path;
  o.tokens = config_.tokens;
  o.web_root = web_root;
  HttpHandlers h;
  h.start_test = [this](const std::string& s, std::string* why) { return Enqueue(s, why); };
  h.recipe = [this] {
    const auto r = recipe();
    nlohmann::json j = r->source;
    j["hash"] = r->hash;
    return j;
  };
  h.current_recipe = [this] { return recipe(); };
  h.change_recipe = [this](const nlohmann::json& j, const ApiToken& who) {
    return ChangeRecipe(j, who);
  };
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
  // Holding the queue lock keeps the sequencer idle until the new recipe is in place.
  std::lock_guard<std::mutex> queue_lock(queue_mu_);
  if (running_test_ || !queue_.empty())
    return refused(RecipeChange::Kind::kBusy,
                   "a test is running or waiting; change the recipe between tests");
  const std::shared_ptr<const Recipe> current = recipe();
  if (next->id != current->id)
    return refused(RecipeChange::Kind::kWrongRecipe,
                   "recipe id must stay '" + current->id +
                       "' (another motor type needs another station config)");
  if (next->version <= current->version)
    return refused(RecipeChange::Kind::kVersionNotIncreased,
                   "version must increase: the station runs version " +
                       std::to_string(current->version) + ", got " + std::to_string(next->version));
  namespace fs = std::filesystem;
  const fs::path path = config_.recipe_path;
  const fs::path kept = path.parent_path() /
                        (path.stem().string() + ".v" + std::to_string(current->version) + ".json");
  try {
    if (!fs::exists(kept)) fs::copy_file(path, kept);
    const fs::path tmp = path.string() + ".tmp";
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out << j.dump(2) << "\n";
      out.flush();
      if (!out) throw std::runtime_error(tmp.string() + ": cannot be written");
    }
    fs::rename(tmp, path);  // atomic on one file system
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
  {
    std::lock_guard<std::mutex> lock(recipe_mu_);
    recipe_ = next;
  }
  sequencer_->SetRecipe(next);
  board_->SetRecipe(next->id, next->hash);
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

int Station::http_port() const { return http_ ? http_->port() : 0; }

db::TestRecord Station::RunTest(const std::string& serial) { return sequencer_->RunTest(serial); }

bool Station::Enqueue(const std::string& serial, std::string* why) {
  std::lock_guard<std::mutex> lock(queue_mu_);
  if (stop_) {
    *why = "station is stopping";
    return false;
  }
  if (running_test_ || !queue_.empty()) {
    *why = "busy: a test is running or waiting";
    return false;
  }
  queue_.push_back(serial);
  queue_cv_.notify_all();
  return true;
}

void Station::Serve() {
  while (true) {
    std::string serial;
    {
      std::unique_lock<std::mutex> lock(queue_mu_);
      // Wakes at least every second to tell systemd's watchdog the loop is alive; a test that
      // hangs stops the pings and gets the daemon restarted.
      int idle_s = 0;
      while (!queue_cv_.wait_for(lock, std::chrono::seconds(1),
                                 [&] { return stop_ || !queue_.empty(); })) {
        NotifyWatchdog();
        if (++idle_s % 60 == 0) sequencer_->PublishLockout();  // a check falls due with time
      }
      NotifyWatchdog();
      if (stop_) return;
      serial = queue_.front();
      queue_.pop_front();
      running_test_ = true;
    }
    const db::TestRecord r = sequencer_->RunTest(serial);
    spdlog::info("[{}] {} {}", r.serial, analysis::ToString(r.outcome),
                 r.reasons.empty() ? "" : r.reasons.front().text);
    std::lock_guard<std::mutex> lock(queue_mu_);
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

}  // namespace eol::station
