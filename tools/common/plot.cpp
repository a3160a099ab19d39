#include "common/plot.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

#ifndef STATSIM_PLOT_DIR
#error "STATSIM_PLOT_DIR (the source tree's tools/plot) is set by tools/common/CMakeLists.txt"
#endif

namespace statsim::tools::plot {
namespace {

std::string errno_text(int err)
{
  return std::error_code(err, std::generic_category()).message();
}

struct Outcome {
  int spawn_error = 0;  // errno of a failed start (ENOENT: no such program); 0 if it ran
  int status = -1;      // exit status, or 128 + signal number
  std::string err;      // what it wrote on stderr
};

// Runs argv[0] (looked up on PATH) with stdout inherited and stderr collected. No shell: the
// arguments reach the program as they are, whatever characters the paths hold.
Outcome run(const std::vector<std::string>& argv)
{
  std::vector<char*> cargv;
  for (const std::string& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);

  // Close-on-exec, so that no other child started meanwhile holds the write end open; the
  // dup2 onto the child's stderr clears the flag there.
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("cannot create a pipe: " + errno_text(errno));
  posix_spawn_file_actions_t actions;
  ::posix_spawn_file_actions_init(&actions);
  ::posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
  pid_t pid = 0;
  Outcome out;
  out.spawn_error = ::posix_spawnp(&pid, cargv[0], &actions, nullptr, cargv.data(), environ);
  ::posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  if (out.spawn_error != 0) {
    ::close(fds[0]);
    return out;
  }
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n > 0) {
      out.err.append(buf, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("waiting for " + argv[0] + ": " + errno_text(errno));
  }
  out.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return out;
}

std::string trimmed(std::string s)
{
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

std::string last_line(const std::string& s)
{
  const std::string t = trimmed(s);
  const auto nl = t.rfind('\n');
  return nl == std::string::npos ? t : t.substr(nl + 1);
}

// Removes the temporary data file on every way out of run_script_on().
struct RemoveOnExit {
  std::string path;
  ~RemoveOnExit() { std::remove(path.c_str()); }
};

}  // namespace

std::filesystem::path script_dir()
{
  return STATSIM_PLOT_DIR;
}

std::string find_python()
{
  std::vector<std::string> candidates;
  const char* chosen = std::getenv("STATSIM_PYTHON");
  if (chosen != nullptr && *chosen != '\0') {
    candidates.push_back(chosen);
  } else {
    // A python3 first on PATH may be one of pyenv, conda or a virtual environment, which do not
    // see the Debian package; Debian's own interpreter does.
    candidates = {"python3", "/usr/bin/python3"};
  }
  std::string tried;
  for (const std::string& python : candidates) {
    const Outcome o = run({python, "-c", "import matplotlib"});
    if (o.spawn_error == 0 && o.status == 0) return python;
    tried += (tried.empty() ? "" : "; ") + python + ": " +
             (o.spawn_error != 0 ? errno_text(o.spawn_error) : last_line(o.err));
  }
  throw std::runtime_error("charts need Python 3 with matplotlib (tried " + tried +
                           "); install Debian's python3-matplotlib (tools/setup.sh does), or set STATSIM_PYTHON "
                           "to a python3 that has matplotlib");
}

void run_script(const std::string& script, const std::vector<std::string>& args)
{
  const std::filesystem::path path = script_dir() / script;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error("plotting script " + path.string() + " not found");
  // -B: no __pycache__ written into the source tree.
  std::vector<std::string> argv{find_python(), "-B", path.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  const Outcome o = run(argv);
  if (o.spawn_error != 0) throw std::runtime_error("cannot start " + argv[0] + ": " + errno_text(o.spawn_error));
  if (o.status != 0) {
    std::string message = trimmed(o.err);
    if (message.empty()) message = path.string() + " failed with status " + std::to_string(o.status);
    // "fig3.py: error: ..." reads "tool: error: fig3.py: ..." once the tool prefixes its own.
    const std::string prefix = script + ": error: ";
    if (message.rfind(prefix, 0) == 0) message.replace(0, prefix.size(), script + ": ");
    throw std::runtime_error(message);
  }
  // Warnings of a run that succeeded (matplotlib building its font cache, ...).
  std::cerr << o.err << std::flush;
}

void run_script_on(const std::string& script, std::string_view data, const std::string& suffix,
                   const std::vector<std::string>& args)
{
  std::string name = (std::filesystem::temp_directory_path() / ("statsim-plot-XXXXXX" + suffix)).string();
  const int fd = ::mkstemps(name.data(), static_cast<int>(suffix.size()));
  if (fd < 0) throw std::runtime_error("cannot create a temporary file for " + script + ": " + errno_text(errno));
  RemoveOnExit guard{name};
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = errno;
      ::close(fd);
      throw std::runtime_error("cannot write " + name + ": " + errno_text(err));
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) throw std::runtime_error("cannot write " + name + ": " + errno_text(errno));
  std::vector<std::string> all{name};
  all.insert(all.end(), args.begin(), args.end());
  run_script(script, all);
}

std::filesystem::path svg_of(const std::filesystem::path& png)
{
  return std::filesystem::path(png).replace_extension(".svg");
}

}  // namespace statsim::tools::plot
