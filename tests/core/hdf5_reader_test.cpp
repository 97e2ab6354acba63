/// Hdf5Reader reads back exactly what Hdf5Writer wrote (bit for bit, shapes kept), lists datasets
/// without following soft links (whose targets it reads) and attributes, and names the file and
/// object in every error.

#include "gpilqg/core/hdf5_reader.hpp"

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "gpilqg/core/hdf5_writer.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

TEST(Hdf5Reader, ReadsBackWhatTheWriterWroteBitForBit) {
  const auto dir = test::temporary_dir("hdf5_reader");
  const auto file = dir / "round_trip.h5";
  Matrix a(2, 3);
  a << 1.0 / 3.0, -2.5e-300, std::numeric_limits<double>::max(), 0.0, -0.0, 7.0;
  const Vector v = Vector::LinSpaced(5, -1.0, 1.0) / 7.0;
  const std::vector<double> cube = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  {
    Hdf5Writer h5(file);
    h5.write_matrix("/g/a", a);
    h5.write_matrix("/g/empty", Matrix(0, 4));
    h5.write_vector("/g/v", v);
    h5.write_scalar("/s", std::acos(-1.0));
    h5.write_array("/g/h/cube", {2, 3, 2}, cube);
    h5.attribute("/", "name", std::string("ünïcode"));
    h5.attribute("/g", "number", 2.75);
    h5.attribute("/g/v", "count", std::int64_t{-3});
    h5.attribute("/", "list", std::vector<std::string>{"a", "", "ccc"});
    h5.link("/alias", "/g/a");
    h5.close();
  }
  const Hdf5Reader h5(file);
  EXPECT_EQ(h5.read_matrix("/g/a"), a);
  EXPECT_EQ(h5.read_matrix("/g/empty").rows(), 0);
  EXPECT_EQ(h5.read_matrix("/g/empty").cols(), 4);
  EXPECT_EQ(h5.read_vector("/g/v"), v);
  EXPECT_EQ(h5.read_scalar("/s"), std::acos(-1.0));
  EXPECT_EQ(h5.read_array("/g/h/cube"), cube);
  EXPECT_EQ(h5.shape("/g/h/cube"), (std::vector<std::uint64_t>{2, 3, 2}));
  EXPECT_EQ(h5.string_attribute("/", "name"), "ünïcode");
  EXPECT_EQ(h5.number_attribute("/g", "number"), 2.75);
  EXPECT_EQ(h5.number_attribute("/g/v", "count"), -3.0);
  EXPECT_EQ(h5.string_list_attribute("/", "list"), (std::vector<std::string>{"a", "", "ccc"}));
  EXPECT_TRUE(h5.has_attribute("/g", "number"));
  EXPECT_FALSE(h5.has_attribute("/g", "missing"));
  EXPECT_TRUE(h5.exists("/g/h/cube"));
  EXPECT_FALSE(h5.exists("/g/nothing/deeper"));
  EXPECT_FALSE(h5.exists("/s/under_a_dataset"));
  EXPECT_EQ(h5.datasets(), (std::vector<std::string>{"/g/a", "/g/empty", "/g/h/cube", "/g/v", "/s"}));
  EXPECT_EQ(h5.datasets("/g/h"), (std::vector<std::string>{"/g/h/cube"}));
  EXPECT_EQ(h5.soft_link_target("/alias"), std::optional<std::string>("/g/a"));
  EXPECT_EQ(h5.soft_link_target("/g/a"), std::nullopt);
  EXPECT_EQ(h5.soft_link_target("/g"), std::nullopt);
  EXPECT_EQ(h5.soft_link_target("/g/nothing/deeper"), std::nullopt);
  EXPECT_EQ(h5.soft_link_target("/s/under_a_dataset"), std::nullopt);
  EXPECT_EQ(h5.attributes("/"), (std::vector<std::string>{"list", "name"}));
  EXPECT_EQ(h5.attributes("/g/v"), (std::vector<std::string>{"count"}));
  EXPECT_TRUE(h5.attributes("/g/h").empty());
  std::filesystem::remove_all(dir);
}

TEST(Hdf5Reader, ErrorsNameTheFileTheObjectAndWhatWasExpected) {
  const auto dir = test::temporary_dir("hdf5_reader_errors");
  const auto file = dir / "bad.h5";
  {
    Hdf5Writer h5(file);
    h5.write_array("/cube", {2, 2, 2}, std::vector<double>(8, 1.0));
    h5.write_vector("/v", Vector::Ones(3));
    h5.close();
  }
  const auto message = [](const std::function<void()>& action) {
    try {
      action();
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const Hdf5Reader h5(file);
  const std::string f = file.string();
  EXPECT_EQ(message([&] { h5.read_matrix("/cube"); }), f + ": dataset '/cube' has shape (2, 2, 2); expected a matrix (2-D)");
  EXPECT_EQ(message([&] { h5.read_scalar("/v"); }), f + ": dataset '/v' has shape (3); expected one value");
  EXPECT_NE(message([&] { h5.read_vector("/missing"); }).find(f + ": reading the shape of dataset '/missing' failed"),
            std::string::npos);
  EXPECT_NE(message([&] { h5.string_attribute("/", "none"); }).find("'/@none'"), std::string::npos);
  EXPECT_EQ(message([&] { Hdf5Reader(dir / "absent.h5"); }), (dir / "absent.h5").string() + ": no such file; expected an HDF5 file");
  std::ofstream(dir / "text.h5") << "not hdf5";
  EXPECT_NE(message([&] { Hdf5Reader(dir / "text.h5"); }).find("opening '/' failed"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gpilqg
