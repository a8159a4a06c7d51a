#!/usr/bin/env bash
# Install whatever is missing (Debian chromium and LinuxCNC, the virtual environment and the
# Python packages) and run every test: lint, unit, property, API and Playwright end-to-end.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi
APT_UPDATED=""
apt_install() {    # Debian packages, one apt-get update per run at most
    if [ -z "$APT_UPDATED" ]; then $SUDO apt-get update -qq; APT_UPDATED=1; fi
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "$@" >/dev/null
}
if [ ! -x /usr/bin/chromium ]; then
    apt_install chromium
fi
# LinuxCNC for `--machine linuxcnc` and tests/linuxcnc (its python module, halcompile and a C
# compiler for the probe comparator); no recommends: they would bring a realtime kernel
if [ ! -x /usr/bin/linuxcnc ] || [ ! -x /usr/bin/halcompile ] || [ ! -x /usr/bin/gcc ]; then
    apt_install --no-install-recommends linuxcnc-uspace linuxcnc-uspace-dev gcc make
fi
# a Chinese font: the ZH screens and the manual's texts in Chromium (else empty boxes)
if [ ! -d /usr/share/fonts/truetype/wqy ]; then
    apt_install --no-install-recommends fonts-wqy-microhei
fi
# PostgreSQL for the plant mode's tests (tests/pgcluster.py starts a private cluster, stops it after)
if ! ls /usr/lib/postgresql/*/bin/initdb >/dev/null 2>&1; then
    apt_install --no-install-recommends postgresql
fi
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
.venv/bin/pip install -q --upgrade pip
.venv/bin/pip install -q -e '.[test]'
.venv/bin/ruff check app engine db tests bench
# types (pyproject [tool.mypy]): engine/ and db/ strict, app/ with its untyped defs checked
.venv/bin/mypy
# import contracts (.importlinter): the layers of design.md §2 and no cycles, function-level imports included
.venv/bin/lint-imports --no-cache >/dev/null || .venv/bin/lint-imports --no-cache
if [ "$#" -gt 0 ]; then exec .venv/bin/python -m pytest "$@"; fi
# Two streams at once, one per core, so the browser and LinuxCNC tests pass "beside a process that
# keeps one core busy", as on CI's shared machine:
# - the LinuxCNC tests (real time, mostly waiting on motion; one LinuxCNC per computer, so never
#   two at once), then the browser tests one at a time (the more sensitive to load: they finish
#   after the other stream);
# - beside them, all the other tests, then the plant mode's (docs/plant.md): the database,
#   migration, concurrency and plant tests again on PostgreSQL, in a private cluster the tests
#   start and stop (tests/pgcluster.py).
# Every part runs; the status is the first failure's. The browser/LinuxCNC stream's output follows
# when both are done. (pytest-xdist spread the browser tests over both workers: its groups do not
# hold with this pytest, and two browsers at once made timing-bound tests fail.)
streams=$(mktemp -d)
(
    part=0
    .venv/bin/python -m pytest -m linuxcnc -p no:cacheprovider --basetemp="$streams/linuxcnc-tmp" \
        --durations=10 || part=$?
    .venv/bin/python -m pytest tests/e2e -m "not linuxcnc" -p no:cacheprovider \
        --basetemp="$streams/browser-tmp" --durations=10 || part=$((part ? part : $?))
    exit "$part"
) >"$streams/browser.log" 2>&1 &
browser=$!
status=0
.venv/bin/python -m pytest --ignore=tests/e2e -m "not linuxcnc" --basetemp="$streams/others-tmp" --durations=15 \
    || status=$?
.venv/bin/python -m pytest --db-engine=postgresql tests/db tests/plant || status=$((status ? status : $?))
wait "$browser" || status=$((status ? status : $?))
echo "--- the LinuxCNC tests, then the browser tests (run beside the others) ---"
cat "$streams/browser.log"
rm -rf "$streams"
exit "$status"
