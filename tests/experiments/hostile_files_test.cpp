/// Files behind the files: what an input names (an HDF5 external link or external storage, a MuJoCo
/// <include> or mesh) is checked like the input itself, an output that is one of the inputs is
/// refused before it replaces that input, and a file-size limit is reported like a full disk
/// (docs/reliability.md). Hostile HDF5 files are made with the HDF5 C API, no Python needed.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "gpilqg/core/hdf5_memory_file.hpp"
#include "gpilqg/core/hdf5_reader.hpp"
#include "gpilqg/core/measurements.hpp"
#include "gpilqg/core/raw_log.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "gpilqg/core/systems.hpp"
#include "gpilqg/experiments/policy_file.hpp"
#include "gpilqg/experiments/profile.hpp"
#include "gpilqg/gp/backend_registry.hpp"
#include "gpilqg/gp/gp_io.hpp"
#include "hostile_inputs.hpp"
#include "test_support.hpp"
#include "tiny_run_config.hpp"

namespace gpilqg {
namespace {

namespace fs = std::filesystem;

fs::path fifo(const fs::path& file) {
  fs::create_directories(file.parent_path());
  EXPECT_EQ(::mkfifo(file.c_str(), 0600), 0) << file;
  return file;
}

/// The gpilqg program run through the shell with `arguments`, killed after 20 s (a blocked reader
/// fails the test instead of hanging it), with at most `max_file_bytes` per written file when > 0.
test::CommandResult run_cli(const std::string& arguments, rlim_t max_file_bytes = 0) {
  const fs::path dir = test::temporary_dir("hostile_files_cli");
  const std::string command = "exec timeout -s KILL 20 '" + test::program_path() + "' " + arguments + " >'" +
                              (dir / "out.txt").string() + "' 2>'" + (dir / "err.txt").string() + "' </dev/null";
  const pid_t child = ::fork();
  if (child == 0) {
    if (max_file_bytes > 0) {
      const rlimit limit{max_file_bytes, max_file_bytes};
      ::setrlimit(RLIMIT_FSIZE, &limit);
    }
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int raw = 0;
  ::waitpid(child, &raw, 0);
  test::CommandResult result;
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = test::read_text(dir / "out.txt");
  result.err = test::read_text(dir / "err.txt");
  return result;
}

// ---- HDF5 files that refer to other files ------------------------------------------------------

/// A cart-pole measurement file of one episode of 5 samples.
void write_measurement_file(const fs::path& file) {
  MeasurementSet set;
  set.system = system_signature("cartpole");
  Episode episode;
  episode.t = Vector::LinSpaced(5, 0.0, 0.08);
  episode.x = Matrix::Zero(5, 4);
  episode.u = Matrix::Ones(5, 1);
  set.episodes.push_back(episode);
  write_measurements(file, set);
}

/// Creates `file` whose /episodes/0/x is made by `make(file_id, path, link_creation)`: a measurement
/// file whose x is replaced, or (with `mat_header`) an HDF5 file holding only that object behind the
/// 512-byte header of a MAT v7.3 file.
void make_hdf5(const fs::path& file, const std::function<void(hid_t, const char*, hid_t)>& make, bool mat_header = false) {
  const hid_t creation = H5Pcreate(H5P_FILE_CREATE);
  if (mat_header) H5Pset_userblock(creation, 512);
  if (!mat_header) write_measurement_file(file);
  const hid_t f = mat_header ? H5Fcreate(file.c_str(), H5F_ACC_TRUNC, creation, H5P_DEFAULT)
                             : H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0) << file;
  const hid_t links = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(links, 1);
  if (!mat_header) H5Ldelete(f, "/episodes/0/x", H5P_DEFAULT);
  make(f, "/episodes/0/x", links);
  H5Pclose(links);
  H5Fclose(f);
  H5Pclose(creation);
  if (mat_header) {
    std::string header(512, '\0');
    const std::string text = "MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Thu Jan  1 00:00:00 1970 HDF5 schema 1.00 .";
    header.replace(0, text.size(), text);
    std::fill(header.begin() + static_cast<long>(text.size()), header.begin() + 116, ' ');
    header[124] = 0x00, header[125] = 0x02, header[126] = 'I', header[127] = 'M';
    std::fstream out(file, std::ios::binary | std::ios::in | std::ios::out);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
  }
}

void external_link(const fs::path& target, hid_t f, const char* path, hid_t links) {
  EXPECT_GE(H5Lcreate_external(target.c_str(), "/x", f, path, links, H5P_DEFAULT), 0);
}

void external_storage(const fs::path& target, hid_t f, const char* path, hid_t links) {
  const hsize_t dims[2] = {4, 4};
  const hid_t space = H5Screate_simple(2, dims, nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  EXPECT_GE(H5Pset_external(dcpl, target.c_str(), 0, 16 * 8), 0);
  const hid_t set = H5Dcreate2(f, path, H5T_IEEE_F64LE, space, links, dcpl, H5P_DEFAULT);
  EXPECT_GE(set, 0);
  H5Dclose(set);
  H5Pclose(dcpl);
  H5Sclose(space);
}

void virtual_dataset(const fs::path& target, hid_t f, const char* path, hid_t links) {
  const hsize_t dims[2] = {4, 4};
  const hid_t space = H5Screate_simple(2, dims, nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  EXPECT_GE(H5Pset_virtual(dcpl, space, target.c_str(), "/x", space), 0);
  const hid_t set = H5Dcreate2(f, path, H5T_IEEE_F64LE, space, links, dcpl, H5P_DEFAULT);
  EXPECT_GE(set, 0);
  H5Dclose(set);
  H5Pclose(dcpl);
  H5Sclose(space);
}

struct OutsideCase {
  std::string name;
  fs::path target;       ///< the file the object refers to
  std::string problem;   ///< after "<file>:/episodes/0/x: "
  std::function<void(const fs::path&, hid_t, const char*, hid_t)> make;
};

std::vector<OutsideCase> outside_cases(const fs::path& dir) {
  const fs::path pipe_h5 = fifo(dir / "pipe.h5"), pipe = fifo(dir / "pipe");
  return {
      {"external link to a FIFO", pipe_h5, "is an external link to " + pipe_h5.string() + ":/x", external_link},
      {"external raw storage in a FIFO", pipe, "keeps its values in the external file " + pipe.string() + " (external raw storage)",
       external_storage},
      {"external raw storage on /dev/zero", "/dev/zero", "keeps its values in the external file /dev/zero (external raw storage)",
       external_storage},
      {"virtual dataset on a FIFO", pipe_h5, "is a virtual dataset mapping the values of " + pipe_h5.string() + ":/x",
       virtual_dataset},
  };
}

/// Every reader of HDF5 files, reading the object at /episodes/0/x where it can be asked to.
struct Hdf5ReaderCase {
  std::string name;
  std::string extension;
  std::function<void(const fs::path&)> read;
};

std::vector<Hdf5ReaderCase> hdf5_readers() {
  return {
      {"measurements", ".h5", [](const fs::path& f) { read_measurements(f, system_signature("cartpole")); }},
      {"Hdf5Reader (results, policies, checkpoints)", ".h5", [](const fs::path& f) { Hdf5Reader(f).read_array("/episodes/0/x"); }},
      {"raw log (HDF5)", ".h5", [](const fs::path& f) { read_raw_log(f); }},
      {"raw log (MAT v7.3)", ".mat", [](const fs::path& f) { read_raw_log(f); }},
      {"policy file", ".h5", [](const fs::path& f) { read_policy_file(f); }},
      {"profile data", ".h5", [](const fs::path& f) {
         ProfileDataOptions options;
         options.system = "cartpole";
         read_profile_data(f, options);
       }},
      {"saved GP", ".h5", [](const fs::path& f) { gp::load_fitted_gp(f, "/episodes", *gp::make_backend("exact")); }},
      {"HDF5 file updated in memory", ".h5", [](const fs::path& f) { open_hdf5_in_memory(f); }},
  };
}

TEST(HostileFiles, EveryHdf5ReaderRefusesObjectsStoredInOtherFiles) {
  const fs::path dir = test::temporary_dir("hostile_files_hdf5");
  for (const OutsideCase& c : outside_cases(dir)) {
    for (const Hdf5ReaderCase& reader : hdf5_readers()) {
      SCOPED_TRACE(reader.name + " on an " + c.name);
      const fs::path file = dir / ("x" + reader.extension);
      make_hdf5(file, [&](hid_t f, const char* path, hid_t links) { c.make(c.target, f, path, links); },
                reader.extension == ".mat");
      const auto outcome = test::call_with_timeout([&] { reader.read(file); }, std::chrono::seconds(10),
                                                   c.target == "/dev/zero" ? fs::path() : c.target);
      if (!outcome.has_value() || !*outcome) {
        ADD_FAILURE() << (outcome.has_value() ? "accepted the file" : "did not return within 10 s");
        continue;
      }
      try {
        std::rethrow_exception(*outcome);
      } catch (const std::exception& e) {
        const std::string expected = file.string() + ":/episodes/0/x: " + c.problem + "; expected data stored in the file itself";
        EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what() << "\nexpected\n" << expected;
      }
    }
  }
}

TEST(HostileFilesCli, TheCommandsRefuseAnExternalLinkToAFifoWithExit2) {
  const fs::path dir = test::temporary_dir("hostile_files_hdf5_cli");
  const fs::path pipe = fifo(dir / "pipe.h5"), file = dir / "x.h5";
  make_hdf5(file, [&](hid_t f, const char* path, hid_t links) { external_link(pipe, f, path, links); });
  const std::string message =
      file.string() + ":/episodes/0/x: is an external link to " + pipe.string() + ":/x; expected data stored in the file itself";
  for (const std::string& arguments : {"data info " + test::quote(file) + " --system cartpole",
                                       "rollout --system cartpole --policy " + test::quote(file) + " --out " + test::quote(dir / "log.csv")}) {
    const auto r = run_cli(arguments);
    EXPECT_EQ(r.status, 2) << arguments << "\n" << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << arguments << "\n" << r.err;
  }
}

// ---- files a MuJoCo model names ----------------------------------------------------------------

constexpr const char* kBody = R"(<worldbody><body><joint name="hinge" type="hinge"/><geom size="0.1" mass="1"/></body></worldbody>)";

struct ModelCase {
  std::string name;
  std::string model;  ///< "main.xml" or "robot.urdf"
  std::vector<std::pair<std::string, std::string>> files;  ///< relative path and text ("FIFO", "ZERO": a FIFO, a link to /dev/zero)
  std::string bad;      ///< the refused file, relative; empty: the model loads
  std::string problem;  ///< after "<bad>: "
};

std::vector<ModelCase> model_cases() {
  const std::string fifo_problem = "is a FIFO (named pipe), not a regular file; expected ";
  return {
      {"an include that is a FIFO", "main.xml", {{"main.xml", "<mujoco>\n<include file=\"inc.xml\"/>\n" + std::string(kBody) + "</mujoco>"}, {"inc.xml", "FIFO"}},
       "inc.xml", fifo_problem + "an MJCF file (<include file=\"inc.xml\"> in MAIN, line 2)"},
      {"a nested include, relative to the main model's folder", "main.xml",
       {{"main.xml", "<mujoco><include file=\"sub/a.xml\"/>" + std::string(kBody) + "</mujoco>"},
        {"sub/a.xml", "<mujoco>\n\n<include file=\"b.xml\"/></mujoco>"},
        {"b.xml", "FIFO"}},
       "b.xml", fifo_problem + "an MJCF file (<include file=\"b.xml\"> in DIR/sub/a.xml, line 3)"},
      {"a mesh in <compiler meshdir> that is a FIFO", "main.xml",
       {{"main.xml", "<mujoco><compiler meshdir=\"meshes\"/><asset><mesh name=\"m\" file=\"pipe.stl\"/></asset>" + std::string(kBody) + "</mujoco>"},
        {"meshes/pipe.stl", "FIFO"}},
       "meshes/pipe.stl", fifo_problem + "a mesh file (<mesh file=\"pipe.stl\"> in MAIN, line 1)"},
      {"a mesh that is /dev/zero", "main.xml",
       {{"main.xml", "<mujoco><asset><mesh name=\"m\" file=\"zero.stl\"/></asset>" + std::string(kBody) + "</mujoco>"}, {"zero.stl", "ZERO"}},
       "zero.stl", "is a character device, not a regular file; expected a mesh file"},
      {"a meshdir set in an included file", "main.xml",
       {{"main.xml", "<mujoco><include file=\"compiler.xml\"/><asset><hfield name=\"h\" file=\"h.png\" size=\"1 1 1 1\"/></asset>" + std::string(kBody) + "</mujoco>"},
        {"compiler.xml", "<mujoco><compiler meshdir=\"assets\"/></mujoco>"},
        {"assets/h.png", "FIFO"}},
       "assets/h.png", fifo_problem + "a height-field file (<hfield file=\"h.png\"> in MAIN, line 1)"},
      {"a cube texture face in <compiler texturedir>", "main.xml",
       {{"main.xml", "<mujoco><compiler texturedir=\"tex\"/><asset><texture name=\"t\" type=\"cube\" fileup=\"up.png\"/></asset>" + std::string(kBody) + "</mujoco>"},
        {"tex/up.png", "FIFO"}},
       "tex/up.png", fifo_problem + "a texture file (<texture fileup=\"up.png\"> in MAIN, line 1)"},
      {"a skin", "main.xml",
       {{"main.xml", "<mujoco><asset><skin file=\"s.skn\"/></asset>" + std::string(kBody) + "</mujoco>"}, {"s.skn", "FIFO"}},
       "s.skn", fifo_problem + "a skin file"},
      {"a URDF mesh (its path stripped, in the meshdir of <mujoco><compiler>)", "robot.urdf",
       {{"robot.urdf", R"(<robot name="r"><mujoco><compiler meshdir="meshes"/></mujoco><link name="base"/>
<link name="arm"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><mesh filename="package://r/stl/pipe.stl"/></geometry></collision></link>
<joint name="hinge" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint></robot>)"},
        {"meshes/pipe.stl", "FIFO"}},
       "meshes/pipe.stl", fifo_problem + "a mesh file (<mesh filename=\"package://r/stl/pipe.stl\"> in MAIN, line 3)"},
      {"an include in a comment and in an attribute's text is no include", "main.xml",
       {{"main.xml", "<mujoco model=\"&lt;include file=&quot;inc.xml&quot;/&gt;\"><!-- <include file=\"inc.xml\"/> -->" + std::string(kBody) + "</mujoco>"},
        {"inc.xml", "FIFO"}},
       "", ""},
  };
}

std::string replaced_everywhere(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) text.replace(at, from.size(), to);
  return text;
}

TEST(HostileFiles, EveryFileAMujocoModelNamesIsCheckedBeforeMujocoOpensIt) {
  const fs::path root = test::temporary_dir("hostile_files_mujoco");
  int k = 0;
  for (const ModelCase& c : model_cases()) {
    SCOPED_TRACE(c.name);
    const fs::path dir = root / std::to_string(k++);
    for (const auto& [name, text] : c.files) {
      if (text == "FIFO") fifo(dir / name);
      else if (text == "ZERO") fs::create_symlink("/dev/zero", dir / name);
      else test::write_text(dir / name, text);
    }
    const fs::path model = dir / c.model;
    const auto outcome = test::call_with_timeout([&] { find_system(model.string()); }, std::chrono::seconds(10),
                                                 c.bad.empty() ? dir / "inc.xml" : dir / c.bad);
    if (!outcome.has_value()) {
      ADD_FAILURE() << "did not return within 10 s";
      continue;
    }
    if (c.bad.empty()) {
      EXPECT_FALSE(*outcome) << "refused a model that names no hostile file";
      continue;
    }
    if (!*outcome) {
      ADD_FAILURE() << "accepted the model";
      continue;
    }
    try {
      std::rethrow_exception(*outcome);
    } catch (const std::exception& e) {
      const std::string expected =
          (dir / c.bad).string() + ": " + replaced_everywhere(replaced_everywhere(c.problem, "MAIN", model.string()), "DIR", dir.string());
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what() << "\nexpected\n" << expected;
    }
  }
}

TEST(HostileFilesCli, SimulateRefusesAModelIncludingAFifoWithExit2) {
  const fs::path dir = test::temporary_dir("hostile_files_mujoco_cli");
  const fs::path model = test::write_text(dir / "main.xml", "<mujoco><include file=\"inc.xml\"/>" + std::string(kBody) + "</mujoco>");
  fifo(dir / "inc.xml");
  const auto r = run_cli("simulate --system " + test::quote(model) + " --out " + test::quote(dir / "data.csv"));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find((dir / "inc.xml").string() + ": is a FIFO (named pipe), not a regular file; expected an MJCF file"),
            std::string::npos)
      << r.err;
}

// ---- an output that is one of the inputs -------------------------------------------------------

TEST(HostileFilesCli, AnOutputThatIsAnInputIsExit2AndTheInputIsKept) {
  const fs::path dir = test::temporary_dir("hostile_files_same");
  // A log and map that import (the output would replace the log); the other inputs need not be
  // valid: the outputs are checked before any input is read.
  const fs::path log = test::write_text(dir / "log.csv", "time,x,xd,th,thd,f\n0.00,0,0,0,0,1\n0.02,0,0,0,0,1\n0.04,0,0,0,0,1\n");
  const fs::path map = test::write_text(dir / "map.toml", "[time]\ncolumn = \"time\"\n[states]\nx = \"x\"\nx_dot = \"xd\"\ntheta = \"th\"\n"
                                                "theta_dot = \"thd\"\n[controls]\nforce = \"f\"\n");
  const fs::path data = test::write_text(dir / "data.csv", "data\n"), model = test::write_text(dir / "model.toml", "# model\n");
  const fs::path config = test::write_text(dir / "plan.toml", "# plan\n"), policy = test::write_text(dir / "policy.h5", "policy\n");
  const fs::path run_config = test::write_text(dir / "run.toml", test::kTinyRun), part = test::write_text(dir / "part.h5", "part\n");
  const fs::path sweep = test::write_text(dir / "sweep.toml", "system = \"cartpole\"\nconfig = \"run.toml\"\n[grid]\n\"loop.rollouts\" = [1, 2]\n");
  fs::create_hard_link(log, dir / "hard.csv");
  fs::create_symlink(data, dir / "link.csv");
  const std::string simulate = "simulate --system cartpole --episodes 1 --steps 20 ";
  struct Case {
    std::string arguments;
    fs::path out;         ///< the file the command would write
    std::string input;    ///< how the message names the input
    fs::path input_file;  ///< the file that must be kept
  };
  const std::vector<Case> cases = {
      {"data import " + test::quote(log) + " --system cartpole --map " + test::quote(map) + " --out {out}", log, "LOG " + log.string(), log},
      {"data import " + test::quote(log) + " --system cartpole --map " + test::quote(map) + " --out {out}", dir / "hard.csv",
       "LOG " + log.string(), log},
      {"data import " + test::quote(log) + " --system cartpole --map " + test::quote(map) + " --out {out}", map, "--map " + map.string(), map},
      {"diagnose --system cartpole --data " + test::quote(data) + " --out {out}", data, "--data " + data.string(), data},
      {"diagnose --system cartpole --data " + test::quote(dir / "link.csv") + " --out {out}", data,
       "--data " + (dir / "link.csv").string(), data},
      {"diagnose --system cartpole --data " + test::quote(data) + " --model " + test::quote(model) + " --write-model {out}", model,
       "--model " + model.string(), model},
      {simulate + "--world-model " + test::quote(model) + " --out {out}", model, "--world-model " + model.string(), model},
      {"plan " + test::quote(config) + " --out {out}", config, "CONFIG " + config.string(), config},
      {"plan " + test::quote(config) + " --data " + test::quote(data) + " --previous " + test::quote(policy) + " --out {out}", policy,
       "--previous " + policy.string(), policy},
      {"rollout --system cartpole --policy " + test::quote(policy) + " --out {out}", policy, "--policy " + policy.string(), policy},
      {"run cartpole --config " + test::quote(run_config) + " --no-plots --out {out}", run_config, "--config " + run_config.string(),
       run_config},
      {"sweep " + test::quote(sweep) + " --no-plots --out {out}", sweep, "SWEEP " + sweep.string(), sweep},
      {"sweep " + test::quote(sweep) + " --no-plots --out {out}", run_config, "config (in the sweep file) " + run_config.string(),
       run_config},
      {"profile " + test::quote(part) + " --backends exact --out {out}", part, "DATA " + part.string(), part},
      {"merge " + test::quote(policy) + " " + test::quote(part) + " --no-plots --out {out}", part, "PART " + part.string(), part},
  };
  for (const Case& c : cases) {
    const std::string arguments = replaced_everywhere(c.arguments, "{out}", test::quote(c.out));
    SCOPED_TRACE(arguments);
    const std::string kept = test::read_text(c.input_file);
    const auto r = run_cli(arguments);
    EXPECT_EQ(r.status, 2) << r.err;
    const std::string option = arguments.find("--write-model") != std::string::npos ? "--write-model" : "--out";
    const std::string message = option + " " + c.out.string() + ": is the same file as " + c.input +
                                ", an input of the command; expected a file that is not one of its inputs";
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err << "\nexpected\n" << message;
    EXPECT_EQ(test::read_text(c.input_file), kept);
  }
}

// ---- a file-size limit -------------------------------------------------------------------------

TEST(HostileFilesCli, AFileSizeLimitIsExit1NamingTheFileAndKeepsThePreviousOne) {
  const fs::path dir = test::temporary_dir("hostile_files_fsize");
  for (const std::string name : {"data.csv", "data.h5"}) {
    SCOPED_TRACE(name);
    const fs::path out = test::write_text(dir / name, "the previous file\n");
    const auto r = run_cli("simulate --system cartpole --episodes 4 --steps 200 --out " + test::quote(out), 16384);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find(out.string() + ": not written: writing failed (File too large)"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_text(out), "the previous file\n");
  }
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << "left behind: " << entry.path();
}

}  // namespace
}  // namespace gpilqg
