#pragma once
/// @file plot_script.hpp
/// Figures are drawn by Python scripts under experiments/plots/ that read only the HDF5 file a
/// command wrote (so any figure can be redrawn, or drawn differently, from the result alone). They run
/// under Debian's /usr/bin/python3, which has python3-matplotlib and python3-h5py (the first python3
/// on PATH may lack them); GPILQG_PYTHON overrides the interpreter and GPILQG_PLOTS_DIR the folder.

#include <filesystem>
#include <string>

namespace gpilqg {

/// The folder holding the plot scripts: $GPILQG_PLOTS_DIR, else the source tree's experiments/plots,
/// else the installed share/gpilqg/plots.
std::filesystem::path plot_script_dir();

/// Checks that `script` exists and the interpreter imports matplotlib and h5py, throwing like
/// run_plot_script; commands call it before long work so that a missing package fails fast.
void require_plotting(const std::string& script);

/// Runs `<interpreter> <dir>/<script> <input> <out_dir>` (out_dir created), without a shell, with the
/// script's stdout sent to stderr (so `--json` output stays one document).
/// Throws std::runtime_error naming the interpreter and the missing packages when matplotlib or h5py
/// cannot be imported, and naming the script and its exit status when it fails.
void run_plot_script(const std::string& script, const std::filesystem::path& input, const std::filesystem::path& out_dir);

}  // namespace gpilqg
