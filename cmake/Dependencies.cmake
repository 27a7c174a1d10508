# All dependencies are Debian bookworm packages (see deploy/install-deps.sh).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(SQLite3 REQUIRED)
find_package(spdlog REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(OpenSSL REQUIRED)  # SHA-256 of recipes
find_package(Threads REQUIRED)
find_package(ZLIB REQUIRED)       # compressed raw curves in the store
find_package(prometheus-cpp CONFIG REQUIRED)  # /metrics (core registry and text format)
find_package(PkgConfig REQUIRED)
pkg_check_modules(FFTW3 REQUIRED IMPORTED_TARGET fftw3)
pkg_check_modules(MODBUS REQUIRED IMPORTED_TARGET libmodbus)
pkg_check_modules(PCRE2 REQUIRED IMPORTED_TARGET libpcre2-8)  # variants' serial patterns, bounded
pkg_check_modules(MOSQUITTO REQUIRED IMPORTED_TARGET libmosquitto)  # results to the MES (MQTT)
pkg_check_modules(PQ REQUIRED IMPORTED_TARGET libpq)  # the plant's central PostgreSQL record
pkg_check_modules(SNDFILE REQUIRED IMPORTED_TARGET sndfile)  # WAV recordings (drivers/io)
# Charts (drivers/io/chart.h): SVG and PNG through cairo's surfaces.
pkg_check_modules(CAIRO REQUIRED IMPORTED_TARGET cairo)
# cpp-httplib 0.11 is compiled; its .pc carries the defines that fix its class layout.
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
# systemd's readiness and watchdog notifications (optional: without it the daemon still runs).
pkg_check_modules(SYSTEMD IMPORTED_TARGET libsystemd)
if(EOL_WITH_ALSA)
  find_package(ALSA REQUIRED)
endif()
