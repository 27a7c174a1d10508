#include "station/daemon/systemd_notify.h"

#if EOL_WITH_SYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace eol::station {

#if EOL_WITH_SYSTEMD
void NotifyReady(const std::string& status) { sd_notify(0, ("READY=1\nSTATUS=" + status).c_str()); }
void NotifyWatchdog() { sd_notify(0, "WATCHDOG=1"); }
void NotifyStopping() { sd_notify(0, "STOPPING=1"); }
#else
void NotifyReady(const std::string&) {}
void NotifyWatchdog() {}
void NotifyStopping() {}
#endif

}  // namespace eol::station
