# What a command-line test script starts with (source it): $SNELL and
# $SCENES required, a work directory removed on exit that also holds the
# kernel caches (the test's own, not the user's), and the ok/bad counters.
set -u
: "${SNELL:?}" "${SCENES:?}"
work=$(mktemp -d)
export SNELL_CACHE_DIR="$work/cache"
trap 'rm -rf "$work"' EXIT
pass=0 fail=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }
