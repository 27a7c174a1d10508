// The plant servers' URLs, read without their client libraries (so the configuration parser
// and its fuzz target link neither libmosquitto nor libpq): the MQTT broker's, parsed, and the
// central database's, redacted for logs and messages.
#pragma once

#include <string>

namespace eol::station {

// "mqtt://host:port" (port optional, 1883) or "mqtts://host:port" (8883) into host and port
// and whether TLS is asked for; false with the reason. A URL with user-info
// ("mqtt://user:password@host") is refused: the credentials go in the "username" and
// "password" fields, which are never logged. The reason never shows a password.
bool ParseMqttUrl(const std::string& url, std::string* host, int* port, bool* tls,
                  std::string* why);

// Any URL as logs and error messages show it: the password of its user-info replaced
// ("postgresql://user:secret@host:5432/db" -> "postgresql://user:***@host:5432/db"), and a
// conninfo's password=... -> password=***. Every log line that prints a URL prints this.
std::string RedactUrl(const std::string& url);

}  // namespace eol::station

namespace eol::station::central {

using eol::station::RedactUrl;

}  // namespace eol::station::central
