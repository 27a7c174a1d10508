// What every request passes before its route's handler (httplib's pre-routing hook), so that
// no handler and no body buffering sees a request the API refuses:
//
//   no Host header, or more than one           400 "bad_host"
//   a Host that is no name of this station     421 "unknown_host": loopback names, the listen
//                                              address, the address connected to and
//                                              HttpOptions::hosts are (DNS rebinding)
//   no route for the path                      404 "not_found"
//   a route, not with this method              405 "method_not_allowed" with Allow
//   GET/HEAD with a body                       400 "unexpected_body"
//   Transfer-Encoding other than "chunked",
//     or with Content-Length                   400 "bad_framing"
//   POST/PUT without either framing            411 "length_required" (httplib would read to EOF)
//   Content-Length above the route's limit     413 "too_large" (the body is not read;
//                                              kMaxBodyBytes, kMaxUploadBytes for figures)
//   POST/PUT not application/json              415 "unsupported_media_type": a cross-site page
//                                              can send text/plain without a preflight
//   POST/PUT with an Origin that is not
//     http://<Host of the request>             403 "cross_origin"
//
// Every response carries Content-Security-Policy: frame-ancestors 'none' and
// X-Frame-Options: DENY. Refused bodies are not read: the connection is closed after the answer.
// Errors httplib answers itself (a malformed request line, a URI too long) get the same JSON body.
#pragma once

#include "station/daemon/http/context.h"
#include "station/daemon/http/server.h"

namespace eol::station::http {

void InstallGate(ApiServer& s, ApiContext& c);

}  // namespace eol::station::http
