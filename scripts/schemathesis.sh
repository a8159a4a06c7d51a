#!/usr/bin/env bash
# The optional long run of the OpenAPI contract (docs/hardening.md, issue 25 item 7): serves the HMI
# (the demo scenario, a new SQLite file in a temporary folder, sign-in on: one level-1 user and a
# level-1 API token the run sends as `Authorization: Bearer`, so the authentication checks see
# wrong credentials refused) and runs schemathesis with every check against its /openapi.json for
# SECONDS (default 900 = 15 minutes). Not part of scripts/test.sh nor of the default pytest run;
# schemathesis comes with the test extras. The operations that would end the run's own access
# (deleting users and tokens, signing out, turning the keyswitch) are left out.
#
#   scripts/schemathesis.sh [SECONDS] [more `st run` options, e.g. --seed 1 --include-path-regex tools]
#
# Exit 0: no check failed. The report (JUnit XML and the failures as pytest code) is left in
# $SCHEMATHESIS_REPORT_DIR (default: the temporary folder, named at the end).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-.venv/bin/python}
[ -x "$PY" ] || PY=python3
ST="$(dirname "$PY")/st"
[ -x "$ST" ] || ST=st
SECONDS_BUDGET=${1:-900}
shift || true
WORK=$(mktemp -d)
REPORT_DIR=${SCHEMATHESIS_REPORT_DIR:-$WORK/report}
PORT=$("$PY" -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
"$PY" -c 'import secrets; print(secrets.token_urlsafe(16))' | "$PY" -m app --db "$WORK/hmi.db" user add fuzz-admin --level 1 >/dev/null
TOKEN=$("$PY" -m app --db "$WORK/hmi.db" token add fuzz --level 1 | head -1)
"$PY" -m app --port "$PORT" --db "$WORK/hmi.db" --time-scale 0 >"$WORK/server.log" 2>&1 &
SERVER=$!
trap 'kill "$SERVER" 2>/dev/null || true; wait "$SERVER" 2>/dev/null || true' EXIT
# the server is up when its schema answers (st waits for it too, at most 60 s)
set +e
"$ST" run "http://127.0.0.1:$PORT/openapi.json" --wait-for-schema 60 --checks all \
    --max-time "$SECONDS_BUDGET" --workers 1 --request-timeout 30 \
    --report junit,pytest --report-dir "$REPORT_DIR" -H "Authorization: Bearer $TOKEN" \
    --exclude-path-regex '^/api/(users|tokens)/' --exclude-path '/api/session' --exclude-path '/api/keyswitch' "$@"
STATUS=$?
set -e
echo "schemathesis exit $STATUS; report in $REPORT_DIR, server log $WORK/server.log"
exit $STATUS
