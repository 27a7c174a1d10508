# The layering: for every library, the folders whose headers it may include. One table, read
# by eol_add_library (cmake/EolTargets.cmake) and checked before the library compiles by
# cmake/CheckLayering.cmake. An include from a folder that is not listed fails the build naming
# the file and the header, so a new folder is refused until it is placed here.
#
# Each entry is a folder of the repository with its trailing '/' (only its own headers, not
# those of its subfolders) or one generated header by name. Arrows point down:
#   analysis <- motor_sim <- analysis_bench
#   analysis <- io <- drivers <- drivers_sim <- emulators, driver_factory
#   drivers <- driver_factory_hardware (the same list without the simulators)
#   analysis <- db
#   analysis, io, db <- station_reports
#   station_reports, drivers, db <- station <- station_command, station_bench
#   station_command + station + driver_factory_hardware = eol-station (the daemon's program)
#   station_command + station + driver_factory + station_bench + emulators = eol (the tool)
# The simulators, emulators and benches are libraries of their own that the station's library
# may not include; the daemon's program does not link them (tests/tools/daemon_symbols.sh).
set(EOL_LAYER_ANALYSIS
    analysis/ analysis/signal/ analysis/model/ analysis/fit/ analysis/qc/ analysis/gap/)
set(EOL_LAYER_DRIVERS ${EOL_LAYER_ANALYSIS} drivers/io/ drivers/ drivers/fixture/ drivers/daq/)
set(EOL_LAYER_DRIVERS_SIM ${EOL_LAYER_DRIVERS} analysis/sim/ drivers/sim/)

set(EOL_ALLOW_eol_analysis ${EOL_LAYER_ANALYSIS})
set(EOL_ALLOW_eol_motor_sim ${EOL_LAYER_ANALYSIS} analysis/sim/)
set(EOL_ALLOW_eol_analysis_bench ${EOL_LAYER_ANALYSIS} analysis/sim/ analysis/bench/)
set(EOL_ALLOW_eol_io ${EOL_LAYER_ANALYSIS} drivers/io/)
set(EOL_ALLOW_eol_drivers ${EOL_LAYER_DRIVERS})
set(EOL_ALLOW_eol_drivers_sim ${EOL_LAYER_DRIVERS_SIM})
set(EOL_ALLOW_eol_emulators ${EOL_LAYER_DRIVERS_SIM} drivers/emulators/)
set(EOL_ALLOW_eol_driver_factory ${EOL_LAYER_DRIVERS_SIM} drivers/factory/)
# Its headers name the simulators' settings types; it links none of them.
set(EOL_ALLOW_eol_driver_factory_hardware ${EOL_ALLOW_eol_driver_factory})
set(EOL_ALLOW_eol_db ${EOL_LAYER_ANALYSIS} db/)
set(EOL_ALLOW_eol_station_reports ${EOL_LAYER_ANALYSIS} drivers/io/ db/ station/reports/)
set(EOL_ALLOW_eol_station ${EOL_LAYER_DRIVERS} drivers/factory/ db/ station/reports/
    station/daemon/ station/daemon/http/ station/daemon/plc/ station/daemon/central/ eol_revision.h)
set(EOL_ALLOW_eol_station_command ${EOL_ALLOW_eol_station} station/cli/)
set(EOL_ALLOW_eol_station_bench ${EOL_ALLOW_eol_station}
    analysis/sim/ analysis/bench/ drivers/sim/ drivers/emulators/ station/bench/)
