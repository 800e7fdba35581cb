// simbot serve [--db URL] [--host H] [--port P] [--data DIR] [--checks
// FILE] [--house DIR] [--workers N | --dask ADDRESS]: a course's competition over HTTP
// (server/simbot_server, Python: FastAPI on uvicorn, SQLAlchemy, Alembic). This command hands
// over to it, with this executable as the simbot it compiles, checks and plays matches with.
#include <filesystem>
#include <memory>

#include "cli/commands.h"
#include "sinks/user_error.h"

namespace simbot::cli {

namespace {

namespace fs = std::filesystem;

struct ServeOptions {
  std::string db, host = "127.0.0.1", data = "simbot-data", checks, house, dask;
  int port = 8000, workers = 2;
};

[[noreturn]] void execServer(const ServeOptions& o) {
#ifdef SIMBOT_PYTHON
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw sinks::UserError("simbot: serve: cannot find this executable's path\n");
  std::vector<std::string> args = {"-m",     "simbot_server", "--simbot", self.string(),
                                   "--host", o.host,          "--port",   std::to_string(o.port),
                                   "--data", o.data};
  if (!o.db.empty()) args.insert(args.end(), {"--db", o.db});
  if (!o.checks.empty()) args.insert(args.end(), {"--checks", o.checks});
  if (!o.house.empty()) args.insert(args.end(), {"--house", o.house});
  if (o.dask.empty())
    args.insert(args.end(), {"--workers", std::to_string(o.workers)});
  else
    args.insert(args.end(), {"--dask", o.dask});
  // The module beside the server: --dask connects by simbot sweep's code.
  execPython(std::string(SIMBOT_SERVER_DIR) + ":" + pythonModuleDir(), std::move(args), "serve");
#else
  (void)o;
  throw sinks::UserError(
      "simbot: serve needs the Python server, which this build does not have (sanitizer builds "
      "leave it out)\n");
#endif
}

}  // namespace

Subcommand addServeCommand(CLI::App& app) {
  auto o = std::make_shared<ServeOptions>();
  auto* cmd = app.add_subcommand(
      "serve",
      "host a course's competition over HTTP: teams, submissions compiled and checked at once "
      "(docs/serve.md)");
  cmd->add_option("--db", o->db,
                  "database URL (default: SQLite, DATA/simbot.sqlite3; PostgreSQL: "
                  "postgresql://USER@HOST/NAME)");
  cmd->add_option("--host", o->host, "address to listen on (default 127.0.0.1)");
  cmd->add_option("--port", o->port, "port (default 8000)")->check(CLI::Range(1, 65535));
  cmd->add_option("--data", o->data,
                  "the server's folder: the database file and the instructor token (default "
                  "simbot-data)");
  cmd->add_option("--checks", o->checks,
                  "the course's expectations file (simbot check), run on every submission")
      ->check(CLI::ExistingFile);
  cmd->add_option("--house", o->house,
                  "house robots: the folder's NAME.dc plays as \"house:NAME\" (e.g. programs)")
      ->check(CLI::ExistingDirectory);
  auto* workers =
      cmd->add_option("--workers", o->workers, "matches run at once, each a process (default 2)")
          ->check(CLI::Range(1, 64));
  cmd->add_option("--dask", o->dask,
                  "run the matches on a Dask cluster instead: tcp://HOST:PORT of a running "
                  "`dask scheduler`, or local:N for N local worker processes; as many at once as "
                  "it has worker threads; the workers run this simbot at this path, so they need "
                  "it there (the same machine or a shared path)")
      ->excludes(workers);
  return {cmd, [o]() -> int { execServer(*o); }};
}

}  // namespace simbot::cli
