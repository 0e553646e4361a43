# Run by `cmake --install` (install(SCRIPT)): writes packaging/pinballd.service
# into <prefix>/lib/systemd/system with its /usr/local paths replaced by the
# prefix the install goes to, so that ExecStart names the pinballd installed.
# Inputs: PINBALL_UNIT_SOURCE (the unit in the source tree).
set(prefix "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}")
file(READ "${PINBALL_UNIT_SOURCE}" unit)
string(REPLACE "/usr/local/" "${CMAKE_INSTALL_PREFIX}/" unit "${unit}")
set(out "${prefix}/lib/systemd/system/pinballd.service")
message(STATUS "Installing: ${out}")
file(WRITE "${out}" "${unit}")
