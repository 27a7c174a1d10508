// systemd's service notifications (sd_notify): readiness, watchdog pings, stopping. No-ops
// when the daemon does not run under systemd or was built without libsystemd.
#pragma once

#include <string>

namespace eol::station {

void NotifyReady(const std::string& status);
void NotifyWatchdog();
void NotifyStopping();

}  // namespace eol::station
