#!/usr/bin/env bash
# Runs a command beside a throwaway PostgreSQL server, for the tests that
# need one (server.api.postgres): a fresh cluster in a new temporary folder,
# listening on a Unix socket in that folder only (no TCP port), with one
# empty database, simbot_test. The command gets its address as
#   SIMBOT_TEST_POSTGRES_URL=postgresql://USER@/simbot_test?host=FOLDER
# and its exit status is this script's; the server is stopped and the
# folder removed when the command ends, fails or is interrupted.
# As root (CI) the cluster belongs to the `postgres` user (initdb refuses
# to run as root); otherwise to the current user. The folder is readable
# by its owner only, which is what keeps others off the socket
# (authentication is `trust`: the server holds test data only).
# Usage: scripts/postgres.sh COMMAND [ARG...]
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: scripts/postgres.sh COMMAND [ARG...]" >&2; exit 2; }
bin=$(printf '%s\n' /usr/lib/postgresql/*/bin | sort -V | tail -n 1)  # the newest
if [ ! -x "$bin/initdb" ]; then
  echo "postgres.sh: no PostgreSQL server in /usr/lib/postgresql/*/bin (scripts/setup.sh installs it)" >&2
  exit 1
fi
folder=$(mktemp -d /tmp/simbot-postgres.XXXXXX)
owner=()
user=$(id -un)
if [ "$(id -u)" -eq 0 ]; then
  chown postgres: "$folder"
  owner=(runuser -u postgres --)
  user=postgres
fi
# The server's own commands, run by the cluster's owner from the folder
# (the caller's directory may be closed to that user).
as_owner() { (cd "$folder" && "${owner[@]}" "$@"); }
finish() {
  local status=$?
  [ ! -e "$folder/data/postmaster.pid" ] || as_owner "$bin/pg_ctl" -D "$folder/data" -m immediate stop > /dev/null 2>&1 || true
  rm -rf "$folder"
  exit "$status"
}
trap finish EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
as_owner "$bin/initdb" -D "$folder/data" --auth=trust --encoding=UTF8 --locale=C --no-sync \
  > "$folder/initdb.log" 2>&1 || { cat "$folder/initdb.log" >&2; exit 1; }
# A test server: no TCP, no durability (the data dies with the folder).
cat >> "$folder/data/postgresql.conf" << EOF
listen_addresses = ''
unix_socket_directories = '$folder'
fsync = off
synchronous_commit = off
full_page_writes = off
EOF
as_owner "$bin/pg_ctl" -D "$folder/data" -l "$folder/server.log" -w -t 60 start > /dev/null ||
  { cat "$folder/server.log" >&2; exit 1; }
"$bin/createdb" -h "$folder" -U "$user" simbot_test
export SIMBOT_TEST_POSTGRES_URL="postgresql://$user@/simbot_test?host=$folder"
echo "postgres.sh: PostgreSQL $("$bin/postgres" --version | awk '{ print $3 }') at $SIMBOT_TEST_POSTGRES_URL"
"$@"
