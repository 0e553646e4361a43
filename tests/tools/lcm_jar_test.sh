#!/bin/sh
# The pinball_lcm_jar target (not built by default) compiles every LCM type
# into a jar that java can load beside lcm.jar.
# Usage: lcm_jar_test.sh BUILD_DIR JAR LCM_JAR JAVAP TYPES...
set -eu
build=$1 jar=$2 lcm_jar=$3 javap=$4
shift 4
fail() { echo "lcm_jar_test: $*" >&2; exit 1; }
cmake --build "$build" --target pinball_lcm_jar >/dev/null || fail "ninja pinball_lcm_jar failed"
[ -f "$jar" ] || fail "$jar not built"
for t in "$@"; do
  "$javap" -cp "$lcm_jar:$jar" "pinball_lcm.$t" | grep -q "LCMEncodable" || fail "pinball_lcm.$t is not an LCM type in the jar"
done
echo "lcm_jar_test: $# types in $jar"
