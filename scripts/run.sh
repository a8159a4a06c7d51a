#!/usr/bin/env bash
# Start the HMI on http://127.0.0.1:8000 with the built-in demo scenario and an embedded
# SQLite file under ./data. Creates the virtual environment on first use.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
if ! .venv/bin/python -c "import app, fastapi, sqlalchemy, numpy" 2>/dev/null; then
    .venv/bin/pip install -q --upgrade pip
    .venv/bin/pip install -q -e .
fi
exec .venv/bin/python -m app "$@"
