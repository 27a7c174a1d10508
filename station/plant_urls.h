// The plant servers' URLs, read without their client libraries (so the configuration parser
// and its fuzz target link neither libmosquitto nor libpq): the MQTT broker's, parsed, and the
// central database's, redacted for logs and messages.
#pragma once

#include <string>

namespace eol::station {

// "mqtt://host:port" (port optional, 1883) or "mqtts://host:port" (8883) into host and port
// and whether TLS is asked for; false with the reason.
bool ParseMqttUrl(const std::string& url, std::string* host, int* port, bool* tls,
                  std::string* why);

}  // namespace eol::station

namespace eol::station::central {

// "postgresql://user:secret@host:5432/db" -> "postgresql://user:***@host:5432/db" (and a
// conninfo's password=... -> password=***): what the logs and error messages show.
std::string RedactUrl(const std::string& url);

}  // namespace eol::station::central
