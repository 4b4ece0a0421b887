#!/usr/bin/env bash
# Run the study-storage tests against a throw-away PostgreSQL (Debian's postgresql package):
# a fresh cluster in a temp dir on a Unix socket, the psycopg driver in .venv, then
# tests/test_study.py with MMS_TEST_DB_URL pointing at it. Not part of the default test run
# (CI's machine need not have PostgreSQL); SQLite is what the default run covers.
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -1)
[ -x "$BIN/initdb" ] || { echo "PostgreSQL is not installed (apt-get install postgresql)"; exit 2; }
.venv/bin/python -c "import psycopg" 2>/dev/null || .venv/bin/pip install -q "psycopg[binary]==3.3.9"
DIR=$(mktemp -d /tmp/mms-pg.XXXXXX)
AS=()
if [ "$(id -u)" = 0 ]; then chown postgres "$DIR"; AS=(runuser -u postgres --); fi
PORT=55439
"${AS[@]}" "$BIN/initdb" -D "$DIR/data" -A trust -U mms >"$DIR/initdb.log"
"${AS[@]}" "$BIN/pg_ctl" -D "$DIR/data" -o "-k $DIR -p $PORT -c listen_addresses=''" -l "$DIR/log" -w start >/dev/null
trap '"${AS[@]}" "$BIN/pg_ctl" -D "$DIR/data" -m fast stop >/dev/null; rm -rf "$DIR"' EXIT
"$BIN/psql" -h "$DIR" -p $PORT -U mms -d postgres -qc "create database study"
MMS_TEST_DB_URL="postgresql+psycopg://mms@/study?host=$DIR&port=$PORT" \
  .venv/bin/python -m pytest tests/test_study.py -p no:cacheprovider "$@"
