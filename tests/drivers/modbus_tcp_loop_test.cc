// The Modbus TCP connection loop (drivers/fixture/modbus_tcp_server.h) with real sockets on
// 127.0.0.1: alone, with a handler that answers reads itself, and under the fixture emulator
// (drivers/emulators/modbus_fixture_server.h) with a crowd of idle, slow, malformed and
// connect-and-close clients around one well-behaved client. The line PLC's server runs the
// same loop (tests/station/plc_crowd_test.cc).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/select.h>

#include <iostream>
#include <memory>
#include <thread>

#include "drivers/emulators/modbus_fixture_server.h"
#include "drivers/fixture/modbus_tcp_server.h"
#include "drivers/sim/sim_bench.h"
#include "tests/support/modbus_crowd.h"
#include "tests/support/wait_until.h"

namespace eol::drivers {
namespace {

using namespace std::chrono_literals;
using eol::testing::ClosedByServer;
using eol::testing::ConnectModbus;
using eol::testing::ModbusClock;
using eol::testing::ReadReply;
using eol::testing::ReadRequest;
using eol::testing::SendAll;

// A loop on a thread of its own, listening on a free port; its handler answers function 3
// with the register's address as its value, and counts the ticks.
class LoopUnderTest {
 public:
  explicit LoopUnderTest(ModbusTcpLoopSettings s)
      : loop_(
            std::move(s), [](int fd, const std::uint8_t* adu, int) { return Answer(fd, adu); },
            [this] { ++ticks_; }) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        ::listen(listen_fd_, 64) != 0 ||
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
      throw std::runtime_error("cannot listen");
    port_ = ntohs(a.sin_port);
    if (::pipe2(wake_, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
    thread_ = std::thread([this] { loop_.Run(listen_fd_, wake_[0]); });
  }
  ~LoopUnderTest() {
    (void)!::write(wake_[1], "x", 1);
    thread_.join();
    ::close(listen_fd_);
    ::close(wake_[0]);
    ::close(wake_[1]);
  }
  LoopUnderTest(const LoopUnderTest&) = delete;
  LoopUnderTest& operator=(const LoopUnderTest&) = delete;

  int port() const { return port_; }
  int ticks() const { return ticks_; }
  ModbusTcpLoopCounts counts() const { return loop_.counts(); }

 private:
  static bool Answer(int fd, const std::uint8_t* adu) {
    const std::vector<std::uint8_t> reply = {adu[0], adu[1], 0, 0,      0,     5,
                                             adu[6], 3,      2, adu[8], adu[9]};
    return SendAll(fd, reply);
  }

  ModbusTcpLoop loop_;
  int listen_fd_ = -1;
  int wake_[2] = {-1, -1};
  int port_ = 0;
  std::atomic<int> ticks_{0};
  std::thread thread_;
};

// One read of register `address` on a connection; true when it was answered with its value.
bool ReadsBack(int fd, int address) {
  if (!SendAll(fd, ReadRequest(42, 1, 3, address, 1))) return false;
  const auto r = ReadReply(fd, 1000ms);
  return r.size() == 11 && r[7] == 3 && ((r[9] << 8) | r[10]) == address;
}

TEST(ModbusTcpLoop, AClientAcceptedInATurnIsServedFromTheNextOn) {
  // The old loops read fds[2 + i] for a client accepted in the same turn: four idle
  // connections at once killed the daemon. Here forty come at once, and all are served.
  ModbusTcpLoopSettings s;
  s.max_clients = 40;
  LoopUnderTest loop(s);
  std::vector<int> fds;
  for (int i = 0; i < 40; ++i) fds.push_back(ConnectModbus(loop.port()));
  for (int i = 0; i < 40; ++i) EXPECT_TRUE(ReadsBack(fds[i], i)) << "client " << i;
  for (int fd : fds) ::close(fd);
  EXPECT_EQ(loop.counts().accepted, 40u);
  EXPECT_EQ(loop.counts().refused, 0u);
}

TEST(ModbusTcpLoop, TheCapRefusesTheExtraAtOnceAndFreesASlotOnClose) {
  ModbusTcpLoopSettings s;
  s.max_clients = 4;
  s.evict_idle_after = std::chrono::hours(1);  // the plain cap (a loaded machine is slow)
  LoopUnderTest loop(s);
  std::vector<int> fds;
  for (int i = 0; i < 4; ++i) fds.push_back(ConnectModbus(loop.port()));
  for (int fd : fds) ASSERT_TRUE(ReadsBack(fd, 1));  // all four are in
  const int extra = ConnectModbus(loop.port());
  EXPECT_TRUE(ClosedByServer(extra, 1000ms));
  ::close(extra);
  EXPECT_EQ(loop.counts().refused, 1u);
  for (int fd : fds) EXPECT_TRUE(ReadsBack(fd, 2));  // the four still are
  ::close(fds.back());
  fds.pop_back();
  ASSERT_TRUE(eol::testing::WaitUntil([&] { return loop.counts().closed_by_peer == 1; }, 2000ms));
  const int next = ConnectModbus(loop.port());
  EXPECT_TRUE(ReadsBack(next, 3));
  ::close(next);
  for (int fd : fds) ::close(fd);
}

TEST(ModbusTcpLoop, AtTheCapANewClientTakesTheIdlestPlaceAndAPollingPlcKeepsItsOwn) {
  // Eight idle connections must not lock the line PLC out (the cap alone would refuse it).
  ModbusTcpLoopSettings s;
  s.max_clients = 4;
  s.evict_idle_after = 1000ms;
  LoopUnderTest loop(s);
  const auto t0 = std::chrono::steady_clock::now();
  const int plc = ConnectModbus(loop.port());
  ASSERT_TRUE(ReadsBack(plc, 1));
  std::vector<int> idle;
  for (int i = 0; i < 3; ++i) idle.push_back(ConnectModbus(loop.port()));
  ASSERT_TRUE(eol::testing::WaitUntil([&] { return loop.counts().accepted == 4; }, 2000ms));
  // Too early: every connection is younger than evict_idle_after, so the extra is refused
  // (checked only when this machine got here in time).
  const int early = ConnectModbus(loop.port());
  if (std::chrono::steady_clock::now() - t0 < 700ms) {
    EXPECT_TRUE(ClosedByServer(early, 1000ms));
    EXPECT_EQ(loop.counts().refused, 1u);
  }
  ::close(early);
  // The PLC keeps polling while the idle ones age; then new clients come one after another.
  for (int round = 0; round < 3; ++round) {
    for (int k = 0; k < 11; ++k) {
      ASSERT_TRUE(ReadsBack(plc, 2)) << "round " << round;
      std::this_thread::sleep_for(100ms);  // the PLC's own poll period
    }
    const int next = ConnectModbus(loop.port());
    EXPECT_TRUE(ReadsBack(next, 3)) << "round " << round;  // it got a place
    idle.push_back(next);
  }
  EXPECT_GE(loop.counts().closed_evicted, 3u);
  EXPECT_TRUE(ReadsBack(plc, 4));  // never the PLC
  ::close(plc);
  for (int fd : idle) ::close(fd);
}

TEST(ModbusTcpLoop, ARequestLeftUnfinishedOrAnIdleConnectionIsClosedAfterItsDeadline) {
  ModbusTcpLoopSettings s;
  s.frame_deadline = 200ms;
  s.idle_timeout = 600ms;
  LoopUnderTest loop(s);
  const int partial = ConnectModbus(loop.port());
  const int idle = ConnectModbus(loop.port());
  const int busy = ConnectModbus(loop.port());
  const auto t0 = ModbusClock::now();
  ASSERT_TRUE(SendAll(partial, {0, 1, 0, 0}));  // half a header
  EXPECT_TRUE(ClosedByServer(partial, 1000ms));
  const double partial_s = std::chrono::duration<double>(ModbusClock::now() - t0).count();
  EXPECT_GE(partial_s, 0.19);
  EXPECT_LT(partial_s, 0.5);
  // The busy client asks every 100 ms for 1 s: never idle, never closed.
  for (int i = 0; i < 10; ++i) {
    EXPECT_TRUE(ReadsBack(busy, i)) << i;
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_TRUE(ClosedByServer(idle, 200ms));  // idle since t0, over 1 s ago
  EXPECT_EQ(loop.counts().closed_slow_frame, 1u);
  EXPECT_EQ(loop.counts().closed_idle, 1u);
  EXPECT_GE(loop.ticks(), 8);  // every 100 ms, whatever the clients do
  ::close(partial);
  ::close(idle);
  ::close(busy);
}

TEST(ModbusTcpLoop, ABadLengthClosesAWrongPduLengthIsAnsweredIllegalDataValue) {
  LoopUnderTest loop(ModbusTcpLoopSettings{});
  for (const std::vector<std::uint8_t>& header :
       {std::vector<std::uint8_t>{0, 1, 0, 0, 0, 1, 1},     // length 1: no function code
        std::vector<std::uint8_t>{0, 1, 0, 0, 0, 255, 1},   // 255: beyond 254
        std::vector<std::uint8_t>{0, 1, 0, 7, 0, 6, 1}}) {  // protocol 7
    const int fd = ConnectModbus(loop.port());
    ASSERT_TRUE(SendAll(fd, header));
    EXPECT_TRUE(ClosedByServer(fd, 1000ms));
    ::close(fd);
  }
  EXPECT_EQ(loop.counts().closed_malformed, 3u);
  // Function 3 with 6 PDU bytes instead of 5: exception 0x83 / 0x03, connection kept.
  const int fd = ConnectModbus(loop.port());
  ASSERT_TRUE(SendAll(fd, {0, 9, 0, 0, 0, 7, 1, 3, 0, 1, 0, 1, 0}));
  const auto r = ReadReply(fd, 1000ms);
  ASSERT_EQ(r.size(), 9u);
  EXPECT_EQ(r[1], 9);
  EXPECT_EQ(r[7], 0x83);
  EXPECT_EQ(r[8], 0x03);
  EXPECT_TRUE(ReadsBack(fd, 5));
  EXPECT_EQ(loop.counts().bad_length, 1u);
  ::close(fd);
}

TEST(ModbusTcpLoop, AClientThatNeverReadsItsRepliesIsClosed) {
  ModbusTcpLoopSettings s;
  s.max_unread_reply_bytes = 2048;
  LoopUnderTest loop(s);
  const int fd = ConnectModbus(loop.port());
  int rcvbuf = 1024;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  std::vector<std::uint8_t> burst;
  for (int i = 0; i < 2000; ++i) {
    const auto one = ReadRequest(static_cast<std::uint16_t>(i), 1, 3, 1, 1);
    burst.insert(burst.end(), one.begin(), one.end());
  }
  ::send(fd, burst.data(), burst.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  EXPECT_TRUE(
      eol::testing::WaitUntil([&] { return loop.counts().closed_not_reading == 1; }, 3000ms));
  const int other = ConnectModbus(loop.port());
  EXPECT_TRUE(ReadsBack(other, 4));
  ::close(other);
  ::close(fd);
}

TEST(ModbusTcpLoop, DescriptorsAreKeptBelowSelectsRange) {
  rlimit r{};
  ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &r), 0);
  if (r.rlim_max != RLIM_INFINITY && r.rlim_max <= FD_SETSIZE)
    GTEST_SKIP() << "the hard limit " << r.rlim_max << " is within FD_SETSIZE already";
  r.rlim_cur = r.rlim_max;  // as a unit file's LimitNOFILE=65536 would set it
  ASSERT_EQ(setrlimit(RLIMIT_NOFILE, &r), 0);
  EXPECT_EQ(KeepDescriptorsBelowFdSetSize(), FD_SETSIZE);
  ASSERT_EQ(getrlimit(RLIMIT_NOFILE, &r), 0);
  EXPECT_EQ(r.rlim_cur, static_cast<rlim_t>(FD_SETSIZE));
  EXPECT_EQ(KeepDescriptorsBelowFdSetSize(), FD_SETSIZE);  // already within: unchanged
}

TEST(ModbusFixtureServerCrowd, EightIdleSlowAndMalformedClientsLeaveAWellBehavedOneServed) {
  auto bench = std::make_shared<SimBench>(SimBenchSettings{});
  ModbusFixtureServerSettings settings;
  settings.link.port = 0;
  settings.max_clients = 16;
  settings.frame_deadline = 5000ms;  // the slow clients' requests are answered
  ModbusFixtureServer server(bench, settings);
  ASSERT_TRUE(server.Start().ok());
  eol::testing::CrowdPlan plan;
  plan.port = server.port();
  plan.unit = settings.link.unit_id;
  plan.function = 4;
  plan.address = settings.map.heartbeat.address;
  ASSERT_EQ(settings.map.heartbeat.table, ModbusTable::kInputRegister);
  const auto f = eol::testing::RunCrowd(plan);
  std::cout << "fixture emulator crowd: " << eol::testing::Describe(plan, f) << "\n";
  EXPECT_EQ(f.idle_connected, 8);
  EXPECT_EQ(f.good_answered, plan.good_requests);
  EXPECT_LT(f.good_max_ms, 100.0);
  EXPECT_EQ(f.slow_answered, plan.slow);
  EXPECT_GT(f.malformed_sent, 0);
  EXPECT_GT(f.churned, 0);
  EXPECT_TRUE(server.running());
}

}  // namespace
}  // namespace eol::drivers
