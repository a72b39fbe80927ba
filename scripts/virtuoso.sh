#!/usr/bin/env bash
# A private Virtuoso Open Source instance on loopback, for pushing a cadkg store to and
# querying it remotely (tests/remote, docs/remote.md).
#
#   scripts/virtuoso.sh install                             apt-get install virtuoso-opensource if missing
#   scripts/virtuoso.sh start DIR [HTTP_PORT [ISQL_PORT]]   install if needed, start an instance in DIR
#   scripts/virtuoso.sh stop DIR                            shut that instance down
#
# start prints KEY=VALUE lines (also kept in DIR/env): the SPARQL endpoint (anonymous,
# read-only), the digest-authenticated SPARQL endpoint and Graph Store Protocol endpoint,
# and the user allowed to write through them. Ports not given are chosen free.
#
# Exit codes: 0 ok, 1 the instance failed (the log's tail is printed), 2 usage,
# 3 Virtuoso is not installed and apt cannot install it (not root, no apt, no network).
set -euo pipefail

BIN=virtuoso-t
ISQL=isql-vt
USER_NAME=cadkg

die() { echo "virtuoso.sh: $*" >&2; exit 1; }

install_virtuoso() {
  if command -v "$BIN" >/dev/null 2>&1 && command -v "$ISQL" >/dev/null 2>&1; then
    return 0
  fi
  if [ "$(id -u)" != 0 ]; then
    echo "virtuoso.sh: cannot install virtuoso-opensource: not root (run as root or install it first)" >&2
    exit 3
  fi
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "virtuoso.sh: cannot install virtuoso-opensource: no apt-get on this machine" >&2
    exit 3
  fi
  echo "virtuoso.sh: installing virtuoso-opensource with apt-get" >&2
  # shellcheck source=scripts/apt.sh
  source "$(dirname "${BASH_SOURCE[0]}")/apt.sh"
  # The package would start its own system-wide server (ports 8890/1111) and ask for a DBA
  # password; we run private instances, so the system one is kept from starting for the
  # install (a policy-rc.d already present is left as it is) and debconf asks nothing.
  local policy=/usr/sbin/policy-rc.d placed=""
  if [ ! -e "$policy" ]; then
    printf '#!/bin/sh\nexit 101\n' >"$policy" && chmod 755 "$policy" && placed=1
  fi
  local log
  log=$(mktemp)
  local status=0
  if ! apt_get install -y -q --no-install-recommends virtuoso-opensource >"$log" 2>&1; then
    # Package lists may be missing or stale on a fresh machine.
    { apt_get update -q && apt_get install -y -q --no-install-recommends virtuoso-opensource; } \
      >"$log" 2>&1 || status=$?
  fi
  [ -n "$placed" ] && rm -f "$policy"
  if [ "$status" != 0 ] || ! command -v "$BIN" >/dev/null 2>&1; then
    echo "virtuoso.sh: cannot install virtuoso-opensource with apt-get:" >&2
    tail -n 5 "$log" >&2
    rm -f "$log"
    exit 3
  fi
  rm -f "$log"
}

port_free() {
  # Nothing answers on the port (bash's /dev/tcp: no ss or netstat needed).
  ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null
}

free_port() {
  local port tries=0
  while [ $tries -lt 200 ]; do
    port=$((20000 + RANDOM % 40000))
    if port_free "$port"; then echo "$port"; return 0; fi
    tries=$((tries + 1))
  done
  die "no free port found"
}

http_status() {
  # The status code of GET $2 on 127.0.0.1:$1, or nothing; plain bash, so no curl is needed.
  local reply
  reply=$(
    exec 2>/dev/null
    exec 3<>"/dev/tcp/127.0.0.1/$1" || exit 0
    printf 'GET %s HTTP/1.0\r\nHost: 127.0.0.1\r\nAccept: application/sparql-results+json\r\n\r\n' "$2" >&3
    timeout 5 head -n 1 <&3 || true
  ) || true
  echo "$reply" | awk '{print $2}'
}

write_ini() {
  local dir=$1 http=$2 isql=$3
  cat >"$dir/virtuoso.ini" <<EOF
; A private cadkg test instance; written by scripts/virtuoso.sh.
[Database]
DatabaseFile = $dir/db/virtuoso.db
ErrorLogFile = $dir/virtuoso.log
LockFile = $dir/db/virtuoso.lck
TransactionFile = $dir/db/virtuoso.trx
xa_persistent_file = $dir/db/virtuoso.pxa
ErrorLogLevel = 7
FileExtend = 200
MaxCheckpointRemap = 2000
Striping = 0
TempStorage = TempDatabase

[TempDatabase]
DatabaseFile = $dir/db/virtuoso-temp.db
TransactionFile = $dir/db/virtuoso-temp.trx
MaxCheckpointRemap = 2000
Striping = 0

[Parameters]
ServerPort = 127.0.0.1:$isql
LiteMode = 0
DisableUnixSocket = 1
DisableTcpSocket = 0
MaxClientConnections = 10
CheckpointInterval = 60
O_DIRECT = 0
CaseMode = 2
MaxStaticCursorRows = 5000
CheckpointAuditTrail = 0
AllowOSCalls = 0
SchedulerInterval = 10
DirsAllowed = ., $dir
ThreadCleanupInterval = 0
ThreadThreshold = 10
ResourcesCleanupInterval = 0
FreeTextBatchSize = 100000
SingleCPU = 0
PrefixResultNames = 0
RdfFreeTextRulesSize = 100
IndexTreeMaps = 64
MaxMemPoolSize = 200000000
MaxQueryMem = 1G
VectorSize = 1000
MaxVectorSize = 1000000
AdjustVectorSize = 0
ThreadsPerQuery = 2
AsyncQueueMaxThreads = 10
NumberOfBuffers = 20000
MaxDirtyBuffers = 15000

[HTTPServer]
ServerPort = 127.0.0.1:$http
ServerRoot = $dir/vsp
MaxClientConnections = 10
DavRoot = DAV
EnabledDavVSP = 0
HTTPProxyEnabled = 0
TempASPXDir = 0
ServerThreads = 10
MaxKeepAlives = 10
KeepAliveTimeout = 10
HTTPThreadSize = 280000
HttpPrintWarningsInOutput = 0
Charset = UTF-8
EnabledGzipContent = 1

[AutoRepair]
BadParentLinks = 0

[Client]
SQL_PREFETCH_ROWS = 100
SQL_PREFETCH_BYTES = 16000
SQL_QUERY_TIMEOUT = 0
SQL_TXN_TIMEOUT = 0

[URIQA]
DynamicLocal = 0
DefaultHost = 127.0.0.1:$http

[SPARQL]
; cadkg reads whole answers: the stock 10000-row cut would truncate big cells silently.
ResultSetMaxRows = 1000000
MaxQueryCostEstimationTime = 400
MaxQueryExecutionTime = 120
EOF
}

isql() {
  # isql PORT PASSWORD SQL...; fails on any SQL error.
  local port=$1 password=$2
  shift 2
  local out
  out=$("$ISQL" "127.0.0.1:$port" dba "$password" "EXEC=$*" 2>&1) || { echo "$out" >&2; return 1; }
  if echo "$out" | grep -q -E '^\*\*\* Error'; then echo "$out" >&2; return 1; fi
}

start() {
  local dir=${1:?usage: virtuoso.sh start DIR [HTTP_PORT [ISQL_PORT]]}
  local http=${2:-} isqlport=${3:-}
  install_virtuoso
  mkdir -p "$dir"
  dir=$(cd "$dir" && pwd)
  if [ -f "$dir/virtuoso.pid" ] && kill -0 "$(cat "$dir/virtuoso.pid")" 2>/dev/null; then
    die "an instance already runs in $dir (pid $(cat "$dir/virtuoso.pid")); stop it first"
  fi
  [ -n "$http" ] || http=$(free_port)
  [ -n "$isqlport" ] || isqlport=$(free_port)
  [ "$http" != "$isqlport" ] || isqlport=$(free_port)
  port_free "$http" || die "port $http is in use"
  port_free "$isqlport" || die "port $isqlport is in use"
  mkdir -p "$dir/db" "$dir/vsp"
  write_ini "$dir" "$http" "$isqlport"
  (cd "$dir" && exec setsid "$BIN" -f -c "$dir/virtuoso.ini" >"$dir/stdout.log" 2>&1 </dev/null) &
  local pid=$!
  echo "$pid" >"$dir/virtuoso.pid"

  local waited=0
  until [ "$(http_status "$http" '/sparql?query=ASK%7B%7D')" = 200 ]; do
    if ! kill -0 "$pid" 2>/dev/null; then
      tail -n 20 "$dir/virtuoso.log" "$dir/stdout.log" >&2 2>/dev/null || true
      die "virtuoso-t exited while starting (see $dir/virtuoso.log)"
    fi
    if [ $waited -ge 180 ]; then
      tail -n 20 "$dir/virtuoso.log" >&2 2>/dev/null || true
      kill "$pid" 2>/dev/null || true
      die "/sparql did not answer within 180 s"
    fi
    sleep 1
    waited=$((waited + 1))
  done

  # A fresh database has the stock dba/dba account; replace that password, and make one user
  # that may write (SPARQL Update and the Graph Store Protocol, both behind digest auth).
  # The anonymous /sparql stays read-only.
  local dba password
  dba=$(head -c 32 /dev/urandom | base64 | tr -dc 'A-Za-z0-9' | head -c 20)
  password=$(head -c 32 /dev/urandom | base64 | tr -dc 'A-Za-z0-9' | head -c 20)
  isql "$isqlport" dba "DB.DBA.USER_CREATE('$USER_NAME', '$password'); \
    GRANT SPARQL_SELECT TO \"$USER_NAME\"; GRANT SPARQL_UPDATE TO \"$USER_NAME\"; \
    DB.DBA.RDF_DEFAULT_USER_PERMS_SET('$USER_NAME', 7); \
    DB.DBA.USER_PASSWORD_SET('dba', '$dba'); checkpoint;" \
    || { kill "$pid" 2>/dev/null; die "could not set up the users (see above)"; }
  (umask 077 && echo "$dba" >"$dir/dba-password")

  local base="http://127.0.0.1:$http"
  cat >"$dir/env" <<EOF
VIRTUOSO_DIR=$dir
VIRTUOSO_PID=$pid
VIRTUOSO_ISQL_PORT=$isqlport
VIRTUOSO_SPARQL=$base/sparql
VIRTUOSO_SPARQL_AUTH=$base/sparql-auth
VIRTUOSO_GRAPH_STORE=$base/sparql-graph-crud-auth
VIRTUOSO_USER=$USER_NAME
VIRTUOSO_PASSWORD=$password
EOF
  chmod 600 "$dir/env"
  cat "$dir/env"
}

stop() {
  local dir=${1:?usage: virtuoso.sh stop DIR}
  [ -f "$dir/virtuoso.pid" ] || { echo "virtuoso.sh: no instance in $dir" >&2; return 0; }
  local pid
  pid=$(cat "$dir/virtuoso.pid")
  if kill -0 "$pid" 2>/dev/null; then
    local port
    port=$(sed -n 's/^VIRTUOSO_ISQL_PORT=//p' "$dir/env" 2>/dev/null || true)
    if [ -n "$port" ] && [ -f "$dir/dba-password" ]; then
      "$ISQL" "127.0.0.1:$port" dba "$(cat "$dir/dba-password")" "EXEC=shutdown;" >/dev/null 2>&1 || true
    fi
    local waited=0
    while kill -0 "$pid" 2>/dev/null && [ $waited -lt 30 ]; do
      [ $waited = 10 ] && kill "$pid" 2>/dev/null
      sleep 1
      waited=$((waited + 1))
    done
    kill -9 "$pid" 2>/dev/null || true
  fi
  rm -f "$dir/virtuoso.pid"
  echo "virtuoso.sh: stopped the instance in $dir" >&2
}

case "${1:-}" in
  install) install_virtuoso ;;
  start) shift; start "$@" ;;
  stop) shift; stop "$@" ;;
  *) echo "usage: virtuoso.sh install | start DIR [HTTP_PORT [ISQL_PORT]] | stop DIR" >&2; exit 2 ;;
esac
