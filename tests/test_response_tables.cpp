// Response models at gathering: the spread each model stores (tools/ref3d/gather.hpp
// response_spread), the tables and JSON of each model (compile, load, rejected when malformed),
// and the cell report of how far the paper's model is from the trials.
#include "ref3d/cell_report.hpp"
#include "ref3d/gather.hpp"
#include "ref3d/ref3d.hpp"
#include "ref3d/signature_json.hpp"

#include "support/temp_dir.hpp"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

using namespace statsim;
using namespace statsim::tools;
using namespace statsim::tools::ref3d;
using namespace statsim::testing;

namespace {

// Two cells of outcomes drawn here: cell 0 Gaussian and independent; cell 1 with w_x and dv_z
// correlated (r = -0.8) and dv_y bimodal (+-1 plus a little noise).
GatherResult synthetic_result(int n)
{
  GatherResult r;
  r.options.name = "synthetic";
  std::uint64_t s = 12345;
  const auto uniform = [&s]() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return (static_cast<double>(s >> 11) + 0.5) / 9007199254740992.0;
  };
  const auto gauss = [&uniform]() { return std::sqrt(-2 * std::log(uniform())) * std::cos(6.283185307179586 * uniform()); };
  r.cell_outcomes.resize(2);
  for (int i = 0; i < n; ++i) {
    Response a, b;
    for (int c = 0; c < 6; ++c) a[c] = 0.1 * c + gauss();
    const double z = gauss();
    const double mode = (i % 2 == 0) ? 1.0 : -1.0;
    b = {z, gauss(), gauss(), gauss(), mode + 0.05 * gauss(), -0.8 * z + 0.6 * gauss()};
    r.cell_outcomes[0].push_back(a);
    r.cell_outcomes[1].push_back(b);
  }
  for (const auto& t : r.cell_outcomes) {
    double mean[6] = {}, sd[6] = {};
    for (const Response& x : t)
      for (int c = 0; c < 6; ++c) mean[c] += x[c] / n;
    for (const Response& x : t)
      for (int c = 0; c < 6; ++c) sd[c] += (x[c] - mean[c]) * (x[c] - mean[c]) / (n - 1);
    for (int c = 0; c < 6; ++c) {
      r.response_mean.push_back(mean[c]);
      r.response_std.push_back(std::sqrt(sd[c]));
    }
  }
  return r;
}

}  // namespace

TEST_CASE("response tables: the correlated model stores a Cholesky factor of each cell's covariance")
{
  GatherResult r = synthetic_result(400);
  r.options.response_model = ResponseModel::correlated_gaussian;
  const std::vector<double> l = response_spread(r);
  REQUIRE(l.size() == 2 * 21);
  for (int cell = 0; cell < 2; ++cell) {
    const std::vector<Response>& t = r.cell_outcomes[static_cast<std::size_t>(cell)];
    const double* mean = &r.response_mean[static_cast<std::size_t>(cell * 6)];
    const double* f = &l[static_cast<std::size_t>(cell * 21)];
    const auto at = [f](int i, int j) { return j > i ? 0.0 : f[i * (i + 1) / 2 + j]; };
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        double cov = 0, llt = 0;
        for (const Response& x : t) cov += (x[i] - mean[i]) * (x[j] - mean[j]) / double(t.size() - 1);
        for (int k = 0; k < 6; ++k) llt += at(i, k) * at(j, k);
        CHECK(llt == doctest::Approx(cov).epsilon(1e-9).scale(1e-9));
      }
  }
  // A constant component (no variance) gives a zero column, not NaN.
  const std::vector<double> a = {4, 2, 0, 2, 1, 0, 0, 0, 0};
  const std::vector<double> c = cholesky_lower(a, 3);
  CHECK(c == std::vector<double>{2, 1, 0, 0, 0, 0});
}

TEST_CASE("response tables: the empirical model keeps outcomes spread over the ranks, centred")
{
  GatherResult r = synthetic_result(30);
  r.options.response_model = ResponseModel::empirical;
  r.options.empirical_outcomes = 6;
  const std::vector<double> o = response_spread(r);
  REQUIRE(o.size() == 2 * 6 * 6);
  // Cell 1: the kept outcomes are those at ranks 2, 7, 12, 17, 22, 27 of 30 in dv_z (they differ
  // from one another as those outcomes do), and they sum to zero: stored about their mean.
  std::vector<Response> sorted = r.cell_outcomes[1];
  std::stable_sort(sorted.begin(), sorted.end(), [](const Response& a, const Response& b) { return a[5] < b[5]; });
  const int ranks[6] = {2, 7, 12, 17, 22, 27};
  double sum[6] = {};
  for (int k = 0; k < 6; ++k) {
    const double* x = &o[static_cast<std::size_t>(36 + k * 6)];
    for (int c = 0; c < 6; ++c) {
      sum[c] += x[c];
      CHECK(x[c] - o[36 + static_cast<std::size_t>(c)] ==
            doctest::Approx(sorted[static_cast<std::size_t>(ranks[k])][c] - sorted[2][c]).epsilon(1e-12));
    }
  }
  for (double v : sum) CHECK(std::fabs(v) < 1e-12);
  // Fewer outcomes than asked for is an error, not a short table.
  r.options.empirical_outcomes = 31;
  CHECK_THROWS_AS(response_spread(r), std::runtime_error);
}

TEST_CASE("response tables: the cell report sees the correlation and the two modes the paper's model drops")
{
  const GatherResult r = synthetic_result(300);
  const CellReport c = cell_report(r);
  CHECK(c.cells == 2);
  CHECK(c.cells_with_strong == 1);
  CHECK(c.strong[0][5] == 1);
  CHECK(c.bimodal[4] == 1);
  CHECK(c.cells_multimodal == 1);
  CHECK(c.not_gaussian[4] == 1);
  CHECK(c.not_gaussian[1] == 0);
  CHECK(cell_report_text(r, c).find("| w_x, dv_z |") != std::string::npos);
}

TEST_CASE("response tables: every model gathers into a table that compiles and a JSON that loads")
{
  TempDir dir("response_tables");
  const std::vector<std::string> base = {"--shape", "box", "--cos-theta", "0.5,1", "--cos-phi", "-1,1",
                                         "--spin-ratios", "0,1", "--height-ratios", "0,1", "--trials", "4",
                                         "--height-trials", "4", "--rest-drops", "12", "--no-body-contacts",
                                         "--quiet"};
  struct Case {
    const char* model;
    std::uint32_t spread;
  };
  for (const Case k : {Case{"paper", 6}, Case{"correlated", 21}, Case{"empirical", 18}}) {
    for (const char* precision : {"f32", "i16"}) {
      CAPTURE(k.model);
      CAPTURE(precision);
      const std::string stem = std::string(k.model) + "_" + precision;
      std::vector<std::string> args = base;
      args.insert(args.end(), {"--response-model", k.model, "--empirical-outcomes", "3", "--precision", precision,
                               "--name", "t_" + stem, "--out", dir.file(stem + ".hpp"), "--json",
                               dir.file(stem + ".json"), "--cell-report", dir.file(stem + "_cells.md")});
      std::ostringstream out, err;
      REQUIRE(run_gather_command(args, out, err) == 0);
      const LoadedSignature3 s = load_signature_json(dir.file(stem + ".json"));
      CHECK(s.i16() == (std::string(precision) == "i16"));
      CHECK(s.view().response.spread_per_cell == k.spread);
      CHECK(s.bytes() == signature_bytes(s.view()));
      const std::string use = dir.write(stem + "_use.cpp", "#include \"" + stem + ".hpp\"\n"
                                        "constexpr statsim::SignatureView<3> v = statsim::tables::t_" + stem + ".view();\n"
                                        "static_assert(v.response.spread_per_cell == " + std::to_string(k.spread) + ");\n");
      const std::string compile = std::string(STATSIM_TEST_CXX) + " -std=c++17 -fsyntax-only -Wall -Wextra " +
                                  "-Wmissing-braces -Werror -I" + STATSIM_TEST_SOURCE_DIR + " -isystem " +
                                  STATSIM_TEST_EIGEN_INCLUDE + " " + use;
      CHECK(std::system(compile.c_str()) == 0);
    }
  }
  // A JSON whose spread does not fit its model is refused with a message.
  nlohmann::json j = nlohmann::json::parse(read_file(dir.file("correlated_f32.json")));
  j["response"]["spread"].erase(0);
  CHECK_THROWS_WITH_AS(parse_signature_json(j.dump(), "bad.json"), doctest::Contains("response.spread"),
                       std::runtime_error);
  j = nlohmann::json::parse(read_file(dir.file("correlated_f32.json")));
  j["response"]["model"] = "lognormal";
  CHECK_THROWS_WITH_AS(parse_signature_json(j.dump(), "bad.json"), doctest::Contains("response.model"),
                       std::runtime_error);
  // A bad model name or outcome count is refused before any work.
  std::vector<std::string> bad = base;
  bad.insert(bad.end(), {"--response-model", "empirical", "--empirical-outcomes", "5", "--out", dir.file("x.hpp")});
  std::ostringstream out, err;
  CHECK(run_gather_command(bad, out, err) != 0);
  CHECK(err.str().find("--empirical-outcomes") != std::string::npos);
}
