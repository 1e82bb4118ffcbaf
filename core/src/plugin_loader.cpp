// Finding plugins on the search path, dlopen-ing them, checking their ABI and creating models.
#include <bodyfit/model_guard.hpp>
#include <bodyfit/plugin_loader.hpp>

#include <bodyfit/shared_object.hpp>

#include <bodyfit/config.hpp>
#include <bodyfit/error.hpp>
#include <bodyfit/parameters.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <dlfcn.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <optional>
#include <set>
#include <system_error>

namespace fs = std::filesystem;

namespace bodyfit {

namespace {

constexpr std::string_view kPrefix = "bodyfit_";
constexpr std::string_view kSuffix = ".so";

using AbiFunction = std::uint32_t (*)();
using CreateFunction = VelocityModel* (*)();
using DestroyFunction = void (*)(VelocityModel*);

/// Closes a dlopen handle unless released (for the failure paths of load_plugin_file).
struct HandleGuard {
  void* handle = nullptr;
  ~HandleGuard() {
    if (handle) dlclose(handle);
  }
  void* release() { return std::exchange(handle, nullptr); }
};

void* require_symbol(void* handle, const fs::path& file, const char* symbol) {
  void* address = shared_object_symbol(handle, symbol);
  if (!address)
    throw file_error(file, fmt::format("not a bodyfit plugin: missing symbol '{}' (build it with BODYFIT_PLUGIN(YourModel))",
                                       symbol));
  return address;
}

/// The model name of a file called bodyfit_<name>.so, or "" for any other file.
std::string model_name_of(const fs::path& file) {
  std::string base = file.filename().string();
  if (base.size() <= kPrefix.size() + kSuffix.size() || !base.starts_with(kPrefix) || !base.ends_with(kSuffix))
    return {};
  return base.substr(kPrefix.size(), base.size() - kPrefix.size() - kSuffix.size());
}

/// Plugin files of a directory, sorted by name (missing or unreadable directories give none).
std::vector<fs::path> plugin_files(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (!model_name_of(it->path()).empty() && it->is_regular_file(ec)) files.push_back(it->path());
  std::sort(files.begin(), files.end());
  return files;
}

/// The plugin directory next to the libbodyfit_core actually loaded (<libdir>/bodyfit/plugins):
/// the build tree and any install prefix share this layout, so a build tree, an installed tree,
/// one that was moved or one installed with `cmake --install --prefix` each find their own plugins.
/// No path of the build tree is compiled in: the installed library holds none.
fs::path plugin_dir_beside_core() {
  const fs::path dir = core_library_directory();
  return dir.empty() ? dir : dir / config::plugin_dir_from_libdir;
}

}  // namespace

std::string abi_string(std::uint32_t abi) { return fmt::format("{}.{}", abi >> 16, abi & 0xffffu); }

// ---- LoadedModel ---------------------------------------------------------------------------------

LoadedModel::LoadedModel(LoadedModel&& other) noexcept
    : handle_(std::exchange(other.handle_, nullptr)),
      model_(std::exchange(other.model_, nullptr)),
      destroy_(std::exchange(other.destroy_, nullptr)),
      file_(std::move(other.file_)),
      abi_(std::exchange(other.abi_, 0)) {}

LoadedModel& LoadedModel::operator=(LoadedModel&& other) noexcept {
  if (this != &other) {
    reset();
    handle_ = std::exchange(other.handle_, nullptr);
    model_ = std::exchange(other.model_, nullptr);
    destroy_ = std::exchange(other.destroy_, nullptr);
    file_ = std::move(other.file_);
    abi_ = std::exchange(other.abi_, 0);
  }
  return *this;
}

LoadedModel::~LoadedModel() { reset(); }

LoadedModel LoadedModel::hosted(std::unique_ptr<VelocityModel> model, std::filesystem::path origin) {
  LoadedModel loaded;
  loaded.model_ = model.release();
  loaded.destroy_ = [](VelocityModel* m) { delete m; };
  loaded.file_ = std::move(origin);
  loaded.abi_ = kPluginAbi;
  return loaded;
}

PluginInfo LoadedModel::info() const {
  return {.file = file_,
          .abi = abi_,
          .name = std::string(model_->name()),
          .version = std::string(model_->version()),
          .description = std::string(model_->description()),
          .parameters = model_->parameters(),
          .outputs = model_->outputs()};
}

void LoadedModel::reset() {
  // The model's code lives in the shared object: destroy it before closing the handle.
  if (model_ && destroy_) destroy_(model_);
  model_ = nullptr;
  destroy_ = nullptr;
  if (handle_) dlclose(handle_);
  handle_ = nullptr;
}

// ---- search path ---------------------------------------------------------------------------------

std::vector<fs::path> plugin_search_path() {
  std::vector<fs::path> dirs;
  auto add = [&](const fs::path& dir) {
    if (dir.empty()) return;
    std::error_code ec;
    auto same = [&](const fs::path& other) { return other == dir || fs::equivalent(other, dir, ec); };
    if (std::none_of(dirs.begin(), dirs.end(), same)) dirs.push_back(dir);
  };
  if (const char* env = std::getenv("BODYFIT_PLUGIN_PATH")) {
    std::string_view rest(env);
    while (true) {
      auto colon = rest.find(':');
      add(fs::path(std::string(rest.substr(0, colon))));
      if (colon == std::string_view::npos) break;
      rest.remove_prefix(colon + 1);
    }
  }
  add(plugin_dir_beside_core());  // the build tree's when running from it, else the prefix's
  add(config::plugin_install_dir);
  return dirs;
}

// ---- loading -------------------------------------------------------------------------------------

LoadedModel load_plugin_file(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw file_error(file, "no such plugin file");
  // Never unloaded (RTLD_NODELETE; dlclose only drops the count): what a plugin pulls in may not
  // survive an unload — libgomp, through a plugin's CHOLMOD, keeps a block that an unload
  // leaks (LeakSanitizer, the sanitize stage) and thread-exit hooks into its unmapped code.
  HandleGuard guard{open_shared_object(file, RTLD_LOCAL | RTLD_NODELETE, "plugin")};

  // The ABI first: nothing else of a plugin built against other headers may be trusted. A crash
  // (or exit()) in the plugin's own code from here on names its file.
  report_model_crashes(file.filename().string());
  auto abi_function = reinterpret_cast<AbiFunction>(require_symbol(guard.handle, file, "bodyfit_plugin_abi"));
  std::uint32_t abi = 0;
  {
    PluginCall call("bodyfit_plugin_abi", -1);
    abi = abi_function();
  }
  if (!abi_compatible(abi))
    throw file_error(file, fmt::format("built against plugin ABI {}, this bodyfit needs {}.x (up to {}): rebuild it "
                                       "against bodyfit {}",
                                       abi_string(abi), kPluginAbiMajor, abi_string(kPluginAbi), config::version));
  auto create = reinterpret_cast<CreateFunction>(require_symbol(guard.handle, file, "bodyfit_create"));
  auto destroy = reinterpret_cast<DestroyFunction>(require_symbol(guard.handle, file, "bodyfit_destroy"));

  VelocityModel* model = nullptr;
  try {
    PluginCall call("bodyfit_create", -1);
    model = create();
  } catch (const std::exception& e) {
    throw file_error(file, fmt::format("bodyfit_create failed: {}", e.what()));
  } catch (...) {
    throw file_error(file, "bodyfit_create failed with an unknown exception");
  }
  if (!model) throw file_error(file, "bodyfit_create returned no model");

  LoadedModel loaded;
  loaded.handle_ = guard.release();
  loaded.model_ = model;
  loaded.destroy_ = destroy;
  loaded.file_ = file;
  loaded.abi_ = abi;
  return loaded;
}

LoadedModel load_model(std::string_view name) {
  if (name.find('/') != std::string_view::npos || name.ends_with(kSuffix)) return load_plugin_file(fs::path(name));
  if (name.empty()) throw InputError("no velocity model given (the [model] table needs name = \"...\")");
  std::string file_name = fmt::format("{}{}{}", kPrefix, name, kSuffix);
  auto dirs = plugin_search_path();
  std::error_code ec;
  for (const auto& dir : dirs)
    if (fs::exists(dir / file_name, ec)) return load_plugin_file(dir / file_name);

  std::set<std::string> available;
  for (const auto& dir : dirs)
    for (const auto& file : plugin_files(dir)) available.insert(model_name_of(file));
  std::vector<std::string> dir_names;
  for (const auto& dir : dirs) dir_names.push_back(dir.string());
  std::string message = fmt::format("unknown velocity model '{}': no {} in {}", name, file_name,
                                    fmt::join(dir_names, ":"));
  std::vector<std::string> names(available.begin(), available.end());
  if (auto near = closest_match(name, names); !near.empty()) message += fmt::format("; did you mean '{}'?", near);
  message += names.empty() ? std::string("; no plugin found (set BODYFIT_PLUGIN_PATH)")
                           : fmt::format(" (available: {})", fmt::join(names, ", "));
  throw InputError(message);
}

void configure_model(LoadedModel& model, const toml::table& parameters, const SurfaceSource& surface) {
  const std::string where = model.file().string();
  std::optional<Parameters> reader;
  try {
    model->set_surface(surface);
    reader.emplace(parameters, model->parameters(), "model");
    model->configure(*reader);
  } catch (const InputError& e) {
    throw file_error(model.file(), fmt::format("configure failed: {}", e.what()));
  } catch (const std::exception& e) {
    throw PluginError(fmt::format("{}: model '{}' failed in configure: {}", where, model->name(), e.what()));
  } catch (...) {
    throw PluginError(fmt::format("{}: model '{}' failed in configure: an exception that is not a std::exception", where,
                                  model->name()));
  }
  reader->check_consumed();  // the case's keys: a message of the case file, not of the plugin
}

namespace {

/// Loads `file` in a child process first ("" when it loads): a plugin that crashes, or ends the
/// process, while it is loaded and described is reported as a failure, not fatal to the listing.
std::string probe_in_child(const fs::path& file) {
  int fds[2];
  if (::pipe(fds) != 0) return {};  // cannot probe: loaded in this process, as without
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    return {};
  }
  if (pid == 0) {
    ::close(fds[0]);
    if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) ::dup2(null, STDERR_FILENO);
    std::string failure;
    try {
      (void)load_plugin_file(file).info();
    } catch (const std::exception& e) {
      failure = e.what();
    } catch (...) {
      failure = file.string() + ": an exception that is not a std::exception";
    }
    for (std::size_t done = 0; done < failure.size();) {
      const ssize_t n = ::write(fds[1], failure.data() + done, failure.size() - done);
      if (n <= 0) break;
      done += std::size_t(n);
    }
    ::_exit(failure.empty() ? 0 : 1);
  }
  ::close(fds[1]);
  std::string message;
  char buffer[1024];
  for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) message.append(buffer, std::size_t(n));
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status))
    return fmt::format("{}: crashed while being loaded ({})", file.string(), ::strsignal(WTERMSIG(status)));
  if (WIFEXITED(status) && WEXITSTATUS(status) == 1 && !message.empty()) return message;
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
    return fmt::format("{}: ended the process while being loaded (exit status {}; it may call exit())", file.string(),
                       WEXITSTATUS(status));
  return {};
}

}  // namespace

std::vector<PluginInfo> discover_plugins(std::vector<std::string>* failures) {
  std::map<std::string, PluginInfo> found;  // by file name: the first directory wins
  std::set<std::string> seen;
  for (const auto& dir : plugin_search_path()) {
    for (const auto& file : plugin_files(dir)) {
      std::string name = model_name_of(file);
      if (!seen.insert(name).second) continue;
      if (std::string failure = probe_in_child(file); !failure.empty()) {
        if (failures) failures->push_back(std::move(failure));
        continue;
      }
      try {
        found.emplace(name, load_plugin_file(file).info());
      } catch (const std::exception& e) {
        if (failures) failures->push_back(e.what());
      }
    }
  }
  std::vector<PluginInfo> result;
  for (auto& [name, info] : found) result.push_back(std::move(info));
  return result;
}

}  // namespace bodyfit
