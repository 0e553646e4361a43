#!/bin/sh
# Installs the build into a fresh prefix and runs the installed programs from
# a folder that is neither the source tree nor the prefix: they must start,
# and `pinball` must find the shipped board in <prefix>/share/pinball.
# Usage: install_test.sh BUILD_DIR WORK_DIR
set -eu
build=$1
work=$2
rm -rf "$work"
mkdir -p "$work/elsewhere"
prefix=$work/prefix
fail() { echo "install_test: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" >"$work/install.log" || { cat "$work/install.log" >&2; fail "cmake --install failed"; }
for f in bin/pinball bin/pinballd bin/pinball-lcm-spy \
         share/pinball/boards/mit1993.board share/pinball/controllers/imitation.json share/pinball/controllers/spastic.json \
         share/pinball/config/lab.example.yaml share/pinball/config/twin.yaml share/pinball/config/randomize.yaml \
         share/pinball/calibration/lab.example.yaml share/pinball/lcmtypes/lcmt_pinball_game_event.lcm \
         share/doc/pinball/daemon.md share/doc/pinball/README.md lib/systemd/system/pinballd.service; do
  [ -e "$prefix/$f" ] || fail "$f not installed"
done
if [ -f "$build/src/bus/pinball_lcmtypes.jar" ]; then
  [ -f "$prefix/share/pinball/java/pinball_lcmtypes.jar" ] || fail "the built types jar was not installed"
  "$prefix/bin/pinball-lcm-spy" --print-command | grep -q "$prefix/share/pinball/java/pinball_lcmtypes.jar" \
    || fail "the installed pinball-lcm-spy does not find the installed jar"
elif [ -e "$prefix/share/pinball/java" ]; then
  fail "share/pinball/java installed without a jar"
fi
if [ -d "$build/src/bus/python" ]; then
  [ -f "$prefix/share/pinball/python/pinball_lcm/lcmt_pinball_game_event.py" ] || fail "python bindings not installed"
fi

cd "$work/elsewhere"
"$prefix/bin/pinballd" --version | grep -q '^pinballd [0-9]' || fail "installed pinballd --version"
"$prefix/bin/pinball" --version | grep -q '^pinball [0-9]' || fail "installed pinball --version"
"$prefix/bin/pinball" --help | grep -q 'sim' || fail "installed pinball --help"
# The board named relative to nothing here: found in the installed data, not the source tree.
"$prefix/bin/pinball" sim boards/mit1993.board --balls 1 --json >sim.json 2>sim.err || { cat sim.err >&2; fail "installed pinball sim"; }
grep -q "\"board\": \"$prefix/share/pinball/boards/mit1993.board\"" sim.json || { cat sim.json >&2; fail "pinball did not take the installed board"; }
# pinballd takes a shipped file named from here as its own default is found, and
# replay finds the default board of the log it reads.
"$prefix/bin/pinballd" --controller controllers/spastic.json --balls 1 --lcm-url "file://$work/elsewhere/run.lcm?mode=w" \
  >pinballd.out 2>pinballd.err || { cat pinballd.err >&2; fail "installed pinballd --controller controllers/spastic.json"; }
grep -q "controller $prefix/share/pinball/controllers/spastic.json" pinballd.err \
  || { cat pinballd.err >&2; fail "pinballd did not take the installed controller"; }
"$prefix/bin/pinball" replay run.lcm --controller controllers/spastic.json >replay.out 2>replay.err \
  || { cat replay.out replay.err >&2; fail "installed pinball replay"; }
grep -q '^reproduced' replay.out || { cat replay.out >&2; fail "the replay from here did not reproduce the run"; }
# The lab example's board, calibration and controller are installed where its relative paths
# lead: replay reads them all and opens no hardware (its decisions differ from the simulated
# run's, exit status 3).
status=0
"$prefix/bin/pinball" replay run.lcm --config config/lab.example.yaml >lab.out 2>lab.err || status=$?
[ "$status" -eq 0 ] || [ "$status" -eq 3 ] || { cat lab.err >&2; fail "replay with the installed lab example"; }
grep -q '^observations [1-9]' lab.out || { cat lab.out lab.err >&2; fail "replay with the installed lab example"; }
# The unit names the pinballd of this prefix.
grep -q "^ExecStart=$prefix/bin/pinballd --config /etc/pinball/pinballd.yaml\$" "$prefix/lib/systemd/system/pinballd.service" \
  || fail "the unit's ExecStart does not name $prefix/bin/pinballd"
grep -q '^LimitRTPRIO=' "$prefix/lib/systemd/system/pinballd.service" || fail "the unit has no LimitRTPRIO"
# systemd's own check, where it is installed (it needs no running systemd): any
# complaint, an unknown key included, fails.
if command -v systemd-analyze >/dev/null 2>&1; then
  complaints=$(systemd-analyze verify --man=no "$prefix/lib/systemd/system/pinballd.service" 2>&1) \
    || fail "systemd-analyze verify: $complaints"
  [ -z "$complaints" ] || fail "systemd-analyze verify: $complaints"
fi
echo "install_test: installed into $prefix; the programs run from $work/elsewhere"
