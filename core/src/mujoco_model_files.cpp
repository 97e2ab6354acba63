/// Every file a MuJoCo model names, checked before MuJoCo opens it (mujoco_model_files.hpp).

#include "mujoco_model_files.hpp"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <tinyxml2.h>

#include "gpilqg/core/input_file.hpp"
#include "gpilqg/core/mujoco_system.hpp"

namespace gpilqg {

namespace {

namespace fs = std::filesystem;

/// Included files nest at most this deep (a file including itself is refused by MuJoCo; this only
/// bounds the scan).
constexpr int kMaxIncludeDepth = 64;

/// A file named by an element of the model, checked once the <compiler> folders are known.
struct Named {
  std::string file;       ///< as written in the attribute
  std::string element;    ///< e.g. "mesh"
  std::string attribute;  ///< e.g. "file"
  std::string source;     ///< the model file that names it
  int line = 0;
  enum class Folder { Mesh, Texture, UrdfMesh } folder = Folder::Mesh;
};

/// "a mesh file (<mesh file="pipe.stl"> in model.xml, line 3)".
std::string description(std::string_view what, const Named& named) {
  return fmt::format("{} (<{} {}=\"{}\"> in {}, line {})", what, named.element, named.attribute, named.file, named.source,
                     named.line);
}

/// Checks `file` like the model itself, unless it does not exist (MuJoCo then reports it when it
/// needs it). Returns whether it exists.
bool check_named_file(const std::string& file, std::uintmax_t max_bytes, const std::string& expected) {
  std::error_code error;
  if (fs::status(file, error).type() == fs::file_type::not_found) return false;
  check_input_file_as<std::invalid_argument>(file, max_bytes, expected);
  return true;
}

class Scan {
 public:
  explicit Scan(const std::string& path) {
    const std::size_t slash = path.rfind('/');
    model_dir_ = slash == std::string::npos ? "" : path.substr(0, slash + 1);  // MuJoCo's "model file dir"
  }

  /// Walks the elements of `text` (the file `source`) in document order, following includes.
  void walk_text(const std::string& text, const std::string& source, int depth) {
    tinyxml2::XMLDocument document;
    if (document.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) return;  // MuJoCo reports it
    walk(document.RootElement(), source, depth);
  }

  /// Checks the asset files with the folders of the last <compiler> attributes; records those that exist.
  void check_assets() {
    for (const Named& named : assets_) {
      const bool texture = named.folder == Named::Folder::Texture;
      std::string file = named.file;
      if (named.folder == Named::Folder::UrdfMesh && strip_path_) file = fs::path(file).filename().string();
      const std::string what = texture                    ? "a texture file"
                               : named.element == "hfield" ? "a height-field file"
                               : named.element == "skin"   ? "a skin file"
                                                           : "a mesh file";
      const std::string path = resolved(file, texture ? texture_dir_ : mesh_dir_);
      if (check_named_file(path, kMaxDataFileBytes, description(what, named))) found(path, what);
    }
  }

  /// The included files and existing assets, in the order they were found.
  const std::vector<ModelDependency>& dependencies() const { return dependencies_; }

 private:
  /// Where MuJoCo looks for the asset `file` of a folder attribute `folder` (meshdir, texturedir).
  std::string resolved(const std::string& file, std::string folder) const {
    if (!file.empty() && file.front() == '/') return file;
    if (!folder.empty() && folder.back() != '/') folder += '/';
    if (!folder.empty() && folder.front() == '/') return folder + file;
    return model_dir_ + folder + file;
  }

  void walk(const tinyxml2::XMLElement* element, const std::string& source, int depth) {
    for (; element != nullptr; element = element->NextSiblingElement()) {
      const std::string name = element->Name();
      const auto attribute = [&](const char* key) -> const char* { return element->Attribute(key); };
      const auto named = [&](const char* key, Named::Folder folder) {
        if (const char* file = attribute(key))
          assets_.push_back({file, name, key, source, element->GetLineNum(), folder});
      };
      if (name == "include") {
        if (const char* file = attribute("file")) include(Named{file, name, "file", source, element->GetLineNum()}, depth);
      } else if (name == "compiler") {
        if (const char* dir = attribute("meshdir")) mesh_dir_ = dir;
        if (const char* dir = attribute("texturedir")) texture_dir_ = dir;
        if (const char* strip = attribute("strippath")) strip_path_ = std::string_view(strip) != "false";
      } else if (name == "mesh" || name == "skin" || name == "hfield") {
        named("file", Named::Folder::Mesh);
        if (name == "mesh") named("filename", Named::Folder::UrdfMesh);
      } else if (name == "texture") {
        for (const char* key : {"file", "fileright", "fileleft", "fileup", "filedown", "filefront", "fileback"})
          named(key, Named::Folder::Texture);
      }
      walk(element->FirstChildElement(), source, depth);
    }
  }

  /// An included file: checked, then scanned itself (MuJoCo reads it relative to the main model's folder).
  void include(const Named& named, int depth) {
    const std::string file = model_dir_ + named.file;
    if (!check_named_file(file, kMaxConfigFileBytes, description("an MJCF file", named))) return;
    std::error_code error;
    const fs::path canonical = fs::weakly_canonical(file, error);
    if (depth >= kMaxIncludeDepth || !included_.insert(error ? file : canonical.string()).second) return;
    found(file, "an included MJCF file");
    walk_text(model_file_text(file), file, depth + 1);
  }

  /// Records `file` once (by its canonical path).
  void found(const std::string& file, const std::string& what) {
    std::error_code error;
    const fs::path canonical = fs::weakly_canonical(file, error);
    if (seen_.insert(error ? file : canonical.string()).second) dependencies_.push_back({file, what});
  }

  std::string model_dir_;
  std::string mesh_dir_, texture_dir_;
  bool strip_path_ = true;  // URDF only: MuJoCo's default for URDF mesh names
  std::vector<Named> assets_;
  std::set<std::string> included_;
  std::set<std::string> seen_;
  std::vector<ModelDependency> dependencies_;
};

}  // namespace

void check_mujoco_model_files(const std::string& path, const std::string& text) {
  Scan scan(path);
  scan.walk_text(text, path, 0);
  scan.check_assets();
}

std::vector<ModelDependency> mujoco_model_dependencies(const std::string& path) {
  check_input_file_as<std::invalid_argument>(path, kMaxConfigFileBytes, "a MuJoCo model file (MJCF or URDF)");
  Scan scan(path);
  scan.walk_text(model_file_text(path), path, 0);
  scan.check_assets();
  return scan.dependencies();
}

std::string model_file_text(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw std::invalid_argument(fmt::format("{}: cannot read the model file", file));
  return text.str();
}

}  // namespace gpilqg
