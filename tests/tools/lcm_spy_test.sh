#!/bin/sh
# scripts/lcm-spy builds lcm-spy's command line without Java 17's fatal
# -Xincgc, with lcm.jar and the pinball types jar on the class path, and the
# JVM accepts it (lcm.spy.Spy --help needs no display).
# Usage: lcm_spy_test.sh SOURCE_DIR WORK_DIR
set -eu
src=$1
work=$2
fail() { echo "lcm_spy_test: $*" >&2; exit 1; }
[ -f /usr/share/java/lcm.jar ] || [ -n "${LCM_JAR:-}" ] || { echo "lcm.jar not installed (liblcm-java): skipped"; exit 77; }
mkdir -p "$work"
: >"$work/types.jar"
cmd=$("$src/scripts/lcm-spy" --print-command --types-jar "$work/types.jar" -l memq://)
echo "$cmd"
case "$cmd" in *-Xincgc*) fail "the command passes -Xincgc" ;; esac
case "$cmd" in *" lcm.spy.Spy -l memq://") ;; *) fail "not lcm.spy.Spy with the arguments passed on" ;; esac
case "$cmd" in *"-cp "*lcm.jar*":$work/types.jar "*) ;; *) fail "lcm.jar and the types jar are not on -cp" ;; esac
case "$cmd" in "CLASSPATH="*"$work/types.jar"*) ;; *) fail "the types jar is not on CLASSPATH" ;; esac
if "$src/scripts/lcm-spy" --types-jar "$work/missing.jar" --print-command 2>/dev/null; then
  fail "a missing types jar was accepted"
fi
if command -v java >/dev/null 2>&1; then
  # Spy's --help exits 1 after its usage; a JVM that refuses an option never gets there.
  "$src/scripts/lcm-spy" --types-jar "$work/types.jar" --help >"$work/help.txt" 2>&1 || true
  grep -q "usage: lcm-spy" "$work/help.txt" || { cat "$work/help.txt" >&2; fail "java did not start lcm.spy.Spy"; }
fi
echo "lcm_spy_test: ok"
