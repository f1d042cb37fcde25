#include "app/output.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <unistd.h>

#include "vrelab_version.hpp"

namespace vrelab::app {

void write_atomic(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  std::error_code dir_error;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), dir_error);
  if (dir_error) throw InputError("cannot create the folder of " + target.string() + ": " + dir_error.message());
  const fs::path tmp = target.string() + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError("cannot write " + tmp.string());
    out << text;
    out.flush();
    if (!out) {
      fs::remove(tmp);
      throw std::runtime_error("writing " + tmp.string() + " failed");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp);
    throw InputError("cannot write " + target.string() + ": " + ec.message());
  }
}

nlohmann::json program_record() {
  return {{"name", "vrelab"}, {"version", kProgramVersion}, {"git", kGitDescribe}};
}

nlohmann::json case_record(const Case& c) { return {{"file", c.path}, {"content", c.content}}; }

nlohmann::json result_record(const std::string& command, const Case& c) {
  return {{"program", program_record()}, {"command", command}, {"case", case_record(c)}, {"seed", c.seed}};
}

}  // namespace vrelab::app
