// The station's finer reason causes (analysis::Reason::cause) and the operator page's languages.
//
// A ReasonCode says what kind of thing went wrong; where one code covers causes an operator
// acts on differently (the door open: close it; the clamp stuck: do not touch the rotor), the
// station names the cause with a stable key "<code>.<cause>". The key is stored with the
// reason in the record and sent in the API; never renamed, only added. Records stored before
// a cause existed have none (nothing is guessed from their text).
//
// Adding a cause: a key here and in kAllCauses, set where it is detected
// (Reason{code, text, std::string(cause::kX)}), and its operator words in every catalogue of
// station/web/i18n/ ("what.<key>" and "do.<key>"; the test
// tests/station/operator_words_test.cc fails while one is missing).
#pragma once

#include <array>
#include <string_view>

namespace eol::station {
namespace cause {

// kInterlock: the fixture's inputs refused the test.
inline constexpr std::string_view kEstopOpen = "interlock.estop_open";
inline constexpr std::string_view kDoorOpen = "interlock.door_open";
inline constexpr std::string_view kNoPart = "interlock.no_part";
inline constexpr std::string_view kClampNotConfirmed = "interlock.clamp_not_confirmed";
inline constexpr std::string_view kClampPressure = "interlock.clamp_pressure";
inline constexpr std::string_view kHeartbeatFrozen = "interlock.heartbeat_frozen";
// The excitation watchdog stopped the excitation (an input, the heartbeat or a stall).
inline constexpr std::string_view kLostDuringExcitation = "interlock.lost_during_excitation";
// kFixture: the fixture controller.
inline constexpr std::string_view kFixtureUnreachable = "fixture.unreachable";
inline constexpr std::string_view kFixtureCommand = "fixture.command_failed";
// The clamp did not open (or the station refuses tests until it reads open again).
inline constexpr std::string_view kClampNotReleased = "fixture.clamp_not_released";
// Safe state could not open the clamp: the rotor is still clamped.
inline constexpr std::string_view kClampLeftClosed = "fixture.clamp_left_closed";
inline constexpr std::string_view kExcitationOffUnconfirmed = "fixture.excitation_off_unconfirmed";
// kAcquisition: the DAQ.
inline constexpr std::string_view kAcquisitionUnavailable = "acquisition.unavailable";
inline constexpr std::string_view kAcquisitionFailed = "acquisition.failed";

inline constexpr std::array kAllCauses = {kEstopOpen,
                                          kDoorOpen,
                                          kNoPart,
                                          kClampNotConfirmed,
                                          kClampPressure,
                                          kHeartbeatFrozen,
                                          kLostDuringExcitation,
                                          kFixtureUnreachable,
                                          kFixtureCommand,
                                          kClampNotReleased,
                                          kClampLeftClosed,
                                          kExcitationOffUnconfirmed,
                                          kAcquisitionUnavailable,
                                          kAcquisitionFailed};

}  // namespace cause

// The operator page's languages: one catalogue station/web/i18n/<code>.json each (English is
// the reference every other must match key for key). The station config's "language" is one
// of these.
inline constexpr std::array<std::string_view, 3> kPageLanguages = {"en", "de", "ja"};

}  // namespace eol::station
