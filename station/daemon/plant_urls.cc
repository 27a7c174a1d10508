#include "station/daemon/plant_urls.h"

#include <regex>

namespace eol::station {

bool ParseMqttUrl(const std::string& url, std::string* host, int* port, bool* tls,
                  std::string* why) {
  *tls = url.rfind("mqtts://", 0) == 0;
  const std::string scheme = *tls ? "mqtts://" : "mqtt://";
  if (url.rfind(scheme, 0) != 0) {
    *why = "must start with mqtt:// or mqtts:// (got '" + RedactUrl(url) + "')";
    return false;
  }
  std::string rest = url.substr(scheme.size());
  if (rest.find('@') != std::string::npos) {
    *why = "must not carry user-info (got '" + RedactUrl(url) +
           "'): put the user in \"username\" and the password in \"password\"";
    return false;
  }
  if (!rest.empty() && rest.back() == '/') rest.pop_back();
  const std::size_t colon = rest.rfind(':');
  *host = colon == std::string::npos ? rest : rest.substr(0, colon);
  *port = *tls ? 8883 : 1883;
  if (colon != std::string::npos) {
    const std::string digits = rest.substr(colon + 1);
    if (digits.empty() || digits.size() > 5 ||
        digits.find_first_not_of("0123456789") != std::string::npos || std::stoi(digits) < 1 ||
        std::stoi(digits) > 65535) {
      *why = "port must be a number in [1, 65535] (got '" + digits + "')";
      return false;
    }
    *port = std::stoi(digits);
  }
  if (host->empty() || host->find('/') != std::string::npos) {
    *why = "no host in '" + RedactUrl(url) + "'";
    return false;
  }
  return true;
}

std::string RedactUrl(const std::string& url) {
  // scheme://user:password@host...: the password up to the authority's last '@'.
  static const std::regex kUserinfo(R"(^([A-Za-z][A-Za-z0-9+.-]*://[^:/@?#]*):[^/?#]*@)");
  static const std::regex kPasswordKey(R"((password\s*=\s*)('[^']*'|\S+))");
  return std::regex_replace(std::regex_replace(url, kUserinfo, "$1:***@"), kPasswordKey, "$1***");
}

}  // namespace eol::station
