# Finds matio (Debian libmatio-dev) through pkg-config as the imported target PkgConfig::matio: the
# reader of MATLAB .mat files behind `gpilqg data import` (docs/data-import.md). matio ships no CMake
# package config, only matio.pc.
find_package(PkgConfig REQUIRED)
pkg_check_modules(matio REQUIRED IMPORTED_TARGET matio)
