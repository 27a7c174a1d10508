#include "station/station.h"

#include <spdlog/spdlog.h>

namespace eol::station {

Station::Station(StationConfig config) : config_(std::move(config)) {
  recipe_ = LoadRecipe(config_.recipe_path);
  spdlog::info("recipe {} v{} ({}), sha256 {}", recipe_.id, recipe_.version, config_.recipe_path,
               recipe_.hash.substr(0, 12));
  store_ = db::Store::Open(config_.db_path);
  if (store_->aborted_on_open() > 0)
    spdlog::warn("store {}: {} test(s) interrupted by a previous stop recorded as ABORTED",
                 config_.db_path, store_->aborted_on_open());
  drivers_ = drivers::MakeDrivers(config_.drivers);
  board_ = std::make_unique<StatusBoard>(config_.station_id, recipe_.id, recipe_.hash);
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
  if (drivers_.bench && drivers_.bench->settings().load_part_on_serial) {
    drivers::SimBench* bench = drivers_.bench.get();
    opts.on_serial = [bench](const std::string& serial) { bench->LoadPart(serial); };
  }
  sequencer_ = std::make_unique<Sequencer>(*drivers_.fixture, *drivers_.daq, *store_, recipe_,
                                           *board_, opts);
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
  o.operator_token = config_.operator_token;
  o.engineer_token = config_.engineer_token;
  o.web_root = web_root;
  o.recipe = recipe_.source;
  o.recipe["hash"] = recipe_.hash;
  http_ = std::make_unique<HttpApi>(*board_, o, [this](const std::string& s, std::string* why) {
    return Enqueue(s, why);
  });
  http_->Start();
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
      queue_cv_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      serial = queue_.front();
      queue_.pop_front();
      running_test_ = true;
    }
    const db::TestRecord r = sequencer_->RunTest(serial);
    spdlog::info("[{}] {} {}", r.serial, analysis::ToString(r.outcome),
                 r.reasons.empty() ? "" : r.reasons.front());
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
