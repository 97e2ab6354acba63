// gpilqg_peer_cases: gpilqg's side of bench/peers/compare_peers.py. Reads the data sets and
// hyperparameters the script wrote (peer_input.hpp), runs the four cases of peer_cases.hpp on
// `--threads` threads with `--repeats` timed repetitions each (`--fit-repeats` for the fit), and
// prints one JSON document on stdout:
//   {"program", "threads", "repeats", "fit_repeats", "input", "blas" (gp/blas_library.hpp),
//    "nlml": [case a per N], "fit": case b, "fitc": case c, "predict": case d,
//    "default_fits": [case e per N of fit_sizes] (with --default-fits)}
// Times are wall-clock seconds (best of k and median). Exit status 2 for a bad input file or
// option, 1 when a case fails.
//   build-bench/bench/gpilqg_peer_cases peers.h5 --threads 2 --repeats 3

#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>
#include <string>

#include "gpilqg/gp/blas_library.hpp"
#include "peer_cases.hpp"
#include "peer_input.hpp"

int main(int argc, char** argv) {
  CLI::App app{"gpilqg's side of bench/peers/compare_peers.py: timed GP cases as JSON"};
  std::string input;
  int threads = 1, repeats = 3, fit_repeats = 1;
  bool default_fits = false;
  app.add_option("input", input, "HDF5 file written by compare_peers.py")->required();
  app.add_option("--threads", threads, "threads inside one evaluation")->check(CLI::Range(1, 256));
  app.add_option("--repeats", repeats, "timed repetitions of the NLML, FITC and prediction cases")
      ->check(CLI::Range(1, 1000));
  app.add_option("--fit-repeats", fit_repeats, "timed repetitions of the whole fit")->check(CLI::Range(1, 1000));
  app.add_flag("--default-fits", default_fits, "also case e: a whole fit at every N of fit_sizes");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  using namespace gpilqg::bench;
  PeerInput in;
  try {
    in = read_peer_input(input);
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  try {
    nlohmann::json out{{"program", "gpilqg_peer_cases"}, {"threads", threads}, {"repeats", repeats},
                       {"fit_repeats", fit_repeats}, {"input", input}, {"blas", gpilqg::gp::blas_library()}};
    out["nlml"] = nlohmann::json::array();
    for (const int n : in.nlml_sizes) out["nlml"].push_back(nlml_case(in.exact, n, in.exact_theta, threads, repeats));
    out["fit"] = fit_case(in.exact, in.fit_size, threads, fit_repeats);
    out["fitc"] = fitc_case(in.fitc, in.fitc_theta, threads, repeats);
    out["predict"] = predict_case(in.exact, in.predict_size, in.exact_theta, in.test_points, threads, repeats);
    if (default_fits) {
      out["default_fits"] = nlohmann::json::array();
      for (const int n : in.fit_sizes) out["default_fits"].push_back(fit_case(in.exact, n, threads, fit_repeats));
    }
    std::cout << out.dump() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
