// The documentation against the files it quotes: every relative link and anchor in the .md files
// resolves, README.md's headline numbers equal the committed measurement files they come from
// (examples/images/bench.csv, examples/images/footprint.csv, tools/fidelity/figures.csv,
// tools/ref2d/figures.csv), and so do the documented sizes (the web page's files,
// examples/web/size.csv; the firmware's footprint table) and the web page's step times
// (examples/web/step_ratio.csv); every chapter README under tools/ and
// examples/ keeps to its length. Runs in the repository root.
#include <doctest/doctest.h>

#include "support/csv.hpp"
#include "support/text_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using statsim::testing::lines_of;
using statsim::testing::read_text;

// ---- CSV --------------------------------------------------------------------------------------

using statsim::testing::csv_fields;

using Row = std::map<std::string, std::string>;

std::vector<Row> read_csv(const fs::path& path)
{
  const auto lines = lines_of(read_text(path));
  REQUIRE_MESSAGE(!lines.empty(), path.string() << " is empty");
  const auto header = csv_fields(lines[0]);
  std::vector<Row> rows;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    if (lines[i].empty())
      continue;
    const auto fields = csv_fields(lines[i]);
    Row row;
    for (std::size_t k = 0; k < header.size() && k < fields.size(); ++k)
      row[header[k]] = fields[k];
    rows.push_back(row);
  }
  return rows;
}

// The one row whose columns have the given values.
Row find_row(const std::vector<Row>& rows, const Row& key, const std::string& file)
{
  const Row* found = nullptr;
  int matches = 0;
  for (const Row& row : rows) {
    bool all = true;
    for (const auto& [column, value] : key) {
      const auto it = row.find(column);
      all = all && it != row.end() && it->second == value;
    }
    if (all) {
      found = &row;
      ++matches;
    }
  }
  std::string what;
  for (const auto& [column, value] : key)
    what += column + "=" + value + " ";
  REQUIRE_MESSAGE(matches == 1, file << ": " << matches << " rows with " << what);
  return *found;
}

double number(const Row& row, const std::string& column)
{
  const auto it = row.find(column);
  REQUIRE_MESSAGE((it != row.end() && !it->second.empty()), "no value in column " << column);
  return std::stod(it->second);
}

// A figures.csv (figure,value,...): the value of one figure.
double figure(const std::vector<Row>& rows, const std::string& name, const std::string& file)
{
  return number(find_row(rows, {{"figure", name}}, file), "value");
}

// ---- how the documents write numbers ----------------------------------------------------------

// `sig` significant figures, trailing zeros kept: 0.7969 -> "0.80", 514.58 -> "515".
std::string sig(double x, int figures)
{
  const int magnitude = x == 0 ? 0 : int(std::floor(std::log10(std::fabs(x))));
  const int decimals = std::max(0, figures - 1 - magnitude);
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, x);
  return text;
}

std::string fixed(double x, int decimals)
{
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, x);
  return text;
}

// Thousands separated by commas: 190153 -> "190,153".
std::string grouped(long long n)
{
  std::string digits = std::to_string(n);
  for (int i = int(digits.size()) - 3; i > 0; i -= 3)
    digits.insert(std::size_t(i), ",");
  return digits;
}

// examples/firmware/footprint.cmake's kilobytes: whole KiB and the tenth below, truncated.
std::string kib(long long bytes)
{
  return std::to_string(bytes / 1024) + "." + std::to_string((bytes % 1024) * 10 / 1024) + " KB";
}

// The numbers written in a piece of Markdown: "2,048", "0.759", "678x"; not the digits of a name
// ("f32", "3D", "Cortex-M4F").
std::vector<std::string> numbers_in(const std::string& text)
{
  std::vector<std::string> found;
  std::size_t i = 0;
  while (i < text.size()) {
    const bool starts = std::isdigit(static_cast<unsigned char>(text[i])) &&
                        (i == 0 || !(std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '.' ||
                                     text[i - 1] == '_'));
    if (!starts) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < text.size() && (std::isdigit(static_cast<unsigned char>(text[j])) ||
                               ((text[j] == ',' || text[j] == '.') && j + 1 < text.size() &&
                                std::isdigit(static_cast<unsigned char>(text[j + 1])))))
      ++j;
    const bool name = j < text.size() && std::isalpha(static_cast<unsigned char>(text[j])) && text[j] != 'x';
    if (!name)
      found.push_back(text.substr(i, j - i));
    i = j;
  }
  return found;
}

std::vector<std::string> table_cells(const std::string& line)
{
  std::vector<std::string> cells;
  std::string cell;
  for (std::size_t i = 1; i < line.size(); ++i) {
    if (line[i] == '|') {
      cells.push_back(cell);
      cell.clear();
    } else {
      cell += line[i];
    }
  }
  return cells;
}

// A row of README.md's headline table: every number in its first three cells (what, statsim,
// reference) is one of the measured figures or one of the row's constants (counts of bodies,
// time steps), and every measured figure is there.
struct HeadlineRow {
  std::string starts;                  // the first cell's beginning
  std::vector<std::string> measured;   // as the row must write them
  std::vector<std::string> constants;  // other numbers the row may write
};

void check_headline(const std::vector<std::string>& readme, const HeadlineRow& spec)
{
  const std::string prefix = "| " + spec.starts;
  const auto it = std::find_if(readme.begin(), readme.end(),
                               [&](const std::string& line) { return line.rfind(prefix, 0) == 0; });
  REQUIRE_MESSAGE(it != readme.end(), "README.md: no headline row starting " << prefix);
  const auto cells = table_cells(*it);
  REQUIRE(cells.size() >= 3);
  std::set<std::string> written;
  for (std::size_t c = 0; c < 3; ++c)
    for (const auto& n : numbers_in(cells[c]))
      written.insert(n);
  for (const auto& n : spec.measured)
    CHECK_MESSAGE(written.count(n) == 1, "README.md headline row '" << spec.starts << "' should say " << n
                                                                      << " (the measurement file's figure): " << *it);
  for (const auto& n : written) {
    const bool known = std::count(spec.measured.begin(), spec.measured.end(), n) +
                           std::count(spec.constants.begin(), spec.constants.end(), n) >
                       0;
    CHECK_MESSAGE(known, "README.md headline row '" << spec.starts << "' writes " << n
                                                     << ", which no measurement file gives: " << *it);
  }
}

bool contains_line(const std::vector<std::string>& lines, const std::string& wanted)
{
  return std::find(lines.begin(), lines.end(), wanted) != lines.end();
}

// ---- links -----------------------------------------------------------------------------------

// GitHub's anchor of a heading: lower case, punctuation but '-' and '_' dropped, spaces to '-'.
std::string slug(const std::string& heading)
{
  std::string s;
  for (const char ch : heading) {
    const auto c = static_cast<unsigned char>(ch);
    if (std::isalnum(c) || ch == '-' || ch == '_' || c >= 0x80)
      s += char(std::tolower(c));
    else if (ch == ' ')
      s += '-';
  }
  return s;
}

std::set<std::string> anchors_of(const fs::path& md)
{
  std::set<std::string> anchors;
  std::map<std::string, int> seen;
  bool code = false;
  for (const auto& line : lines_of(read_text(md))) {
    if (line.rfind("```", 0) == 0)
      code = !code;
    if (code || line.empty() || line[0] != '#')
      continue;
    const auto text = line.find_first_not_of('#');
    if (text == std::string::npos || line[text] != ' ')
      continue;
    std::string base = slug(line.substr(text + 1));
    const int n = seen[base]++;
    anchors.insert(n == 0 ? base : base + "-" + std::to_string(n));
  }
  return anchors;
}

std::vector<fs::path> markdown_files()
{
  std::vector<fs::path> files;
  for (auto it = fs::recursive_directory_iterator("."); it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && (name.rfind("build", 0) == 0 || name == "node_modules" || name[0] == '.')) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file() && it->path().extension() == ".md")
      files.push_back(it->path().lexically_normal());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The targets of the Markdown links and images in a file, outside code blocks and code spans.
std::vector<std::string> link_targets(const std::string& text)
{
  std::vector<std::string> targets;
  bool block = false;
  for (const auto& line : lines_of(text)) {
    if (line.rfind("```", 0) == 0) {
      block = !block;
      continue;
    }
    if (block)
      continue;
    bool span = false;
    for (std::size_t i = 0; i + 1 < line.size(); ++i) {
      if (line[i] == '`')
        span = !span;
      if (span || line[i] != ']' || line[i + 1] != '(')
        continue;
      const auto end = line.find(')', i + 2);
      if (end == std::string::npos)
        continue;
      std::string target = line.substr(i + 2, end - i - 2);
      if (const auto space = target.find(' '); space != std::string::npos)
        target = target.substr(0, space);  // [a](path "title")
      targets.push_back(target);
    }
  }
  return targets;
}

}  // namespace

TEST_CASE("docs: every relative link and anchor in the .md files resolves")
{
  const auto files = markdown_files();
  REQUIRE(std::count(files.begin(), files.end(), fs::path("README.md")) == 1);
  int links = 0;
  for (const auto& md : files) {
    for (const auto& target : link_targets(read_text(md))) {
      if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0)
        continue;
      ++links;
      const auto hash = target.find('#');
      const std::string file = target.substr(0, hash);
      const fs::path path = file.empty() ? md : (md.parent_path() / file).lexically_normal();
      CHECK_MESSAGE(fs::exists(path), md.string() << ": link to " << target << ": no file " << path.string());
      if (hash == std::string::npos || !fs::exists(path))
        continue;
      const std::string anchor = target.substr(hash + 1);
      CHECK_MESSAGE(path.extension() == ".md", md.string() << ": anchor into a file that is not Markdown: " << target);
      if (path.extension() == ".md")
        CHECK_MESSAGE(anchors_of(path).count(anchor) == 1,
                      md.string() << ": link to " << target << ": no heading with anchor #" << anchor << " in "
                                  << path.string());
    }
  }
  CHECK(links > 100);
}

TEST_CASE("docs: the link checker's anchors and numbers")
{
  CHECK(slug("Body-body statistics (`statsim gather-pairs`, `statsim gather-pairs2d`)") ==
        "body-body-statistics-statsim-gather-pairs-statsim-gather-pairs2d");
  CHECK(slug("Where the goals stand (2026-12-04)") == "where-the-goals-stand-2026-12-04");
  CHECK(numbers_in("Bullet, 7 spheres: 196 (31.8x) at 1/60 s, f32, 3D, 2,048") ==
        std::vector<std::string>{"7", "196", "31.8", "1", "60", "2,048"});
  CHECK(sig(0.7969, 2) == "0.80");
  CHECK(sig(514.583, 3) == "515");
  CHECK(kib(84068) == "82.0 KB");
  CHECK(grouped(190153) == "190,153");
}

TEST_CASE("docs: README.md's headline numbers are those of the committed measurement files")
{
  const auto readme = lines_of(read_text("README.md"));

  // tools/bench/README.md's run: thread CPU time per step (cpu_ms), Bullet with sweep-and-prune.
  const std::string bench_file = "examples/images/bench.csv";
  const auto bench = read_csv(bench_file);
  const auto cpu = [&](const std::string& method, const std::string& n, const std::string& broadphase) {
    return number(find_row(bench, {{"method", method}, {"n", n}, {"broadphase", broadphase}}, bench_file), "cpu_ms");
  };
  const double s1k = cpu("statistical", "1000", "auto");
  const double full1k = cpu("full", "1000", "sap");
  const double s10k = cpu("statistical", "10000", "auto");
  const double sphere10k = cpu("sphere", "10000", "sap");
  const double spheres7_10k = cpu("spheres7", "10000", "sap");
  const double s100k = cpu("statistical", "100000", "auto");
  check_headline(readme, {"speed, 1,000 bunnies", {sig(s1k, 3), sig(full1k, 3), sig(full1k / s1k, 3)}, {"1,000", "2,048"}});
  check_headline(readme, {"speed, 10,000 bunnies",
                          {sig(s10k, 3), sig(sphere10k, 3), sig(sphere10k / s10k, 3), sig(spheres7_10k, 3),
                           sig(spheres7_10k / s10k, 3)},
                          {"10,000", "2,048", "7"}});
  check_headline(readme, {"speed, 100,000 bunnies",
                          {sig(s100k, 3), sig(s100k / 100000 * 1000, 2), sig((s100k / 100000) / (s10k / 10000), 2)},
                          {"100,000", "10,000"}});

  // tools/ref2d/figures.csv: compare2d's squares with hull contacts.
  const std::string ref2d_file = "tools/ref2d/figures.csv";
  const auto ref2d = read_csv(ref2d_file);
  const double ms2d = figure(ref2d, "square_ms_per_step_statsim", ref2d_file);
  const double box2d_ms = figure(ref2d, "square_ms_per_step_box2d", ref2d_file);
  check_headline(readme, {"speed, 2D", {sig(ms2d, 3), sig(box2d_ms, 3), sig(box2d_ms / ms2d, 2)}, {"100"}});

  // tools/fidelity/figures.csv: single bunny drops and the box heap.
  const std::string fid_file = "tools/fidelity/figures.csv";
  const auto fid = read_csv(fid_file);
  const auto f = [&](const std::string& name) { return figure(fid, name, fid_file); };
  check_headline(readme, {"accuracy, single bunny drops",
                          {fixed(f("bunny_noise_floor_summary_error"), 3), fixed(f("bunny_statistical_summary_error"), 3),
                           grouped(std::llround(f("bunny_table_bytes"))), fixed(f("bunny_full_60hz_summary_error"), 3),
                           fixed(f("bunny_sphere_summary_error"), 3)},
                          {"1", "60"}});
  check_headline(readme, {"accuracy, rest poses",
                          {fixed(f("bunny_statistical_rest_tvd"), 3), fixed(f("bunny_full_60hz_rest_tvd"), 3),
                           fixed(f("bunny_sphere_rest_tvd"), 3)},
                          {"1", "60"}});
  const double pile = figure(ref2d, "square_pile_height_statsim_m", ref2d_file);
  const double pile_box2d = figure(ref2d, "square_pile_height_box2d_m", ref2d_file);
  check_headline(readme, {"accuracy, piles",
                          {sig(pile, 3), fixed(f("box_heap_angle_statistical_deg"), 1), sig(pile_box2d, 3),
                           fixed((pile / pile_box2d - 1) * 100, 1), fixed(f("box_heap_angle_reference_deg"), 1),
                           fixed(f("box_heap_reference_rate_hz"), 0)},
                          {"10", "100", "1"}});

  // examples/firmware/README.md's footprint table: the 1,024-box variants.
  const std::string fw_file = "examples/images/footprint.csv";
  const auto fw = read_csv(fw_file);
  const Row i16 = find_row(fw, {{"variant", "fw_box_1024_i16"}}, fw_file);
  const Row f32 = find_row(fw, {{"variant", "fw_box_1024_f32"}}, fw_file);
  const auto kb_number = [](double bytes) {
    const std::string s = kib(std::llround(bytes));
    return s.substr(0, s.size() - 3);
  };
  check_headline(readme, {"footprint, Cortex-M4F flash",
                          {kb_number(number(i16, "code_bytes")), kb_number(number(i16, "tables_bytes")),
                           kb_number(number(f32, "tables_bytes"))},
                          {}});
  check_headline(readme, {"footprint, Cortex-M4F RAM per 3D body",
                          {fixed(number(i16, "world3_per_body"), 0)},
                          {grouped(std::llround(number(i16, "bodies")))}});
}

TEST_CASE("docs: tools/bench/README.md's table of thread CPU time is examples/images/bench.csv")
{
  const auto chapter = lines_of(read_text("tools/bench/README.md"));
  const std::string file = "examples/images/bench.csv";
  const auto bench = read_csv(file);
  const auto title = std::find(chapter.begin(), chapter.end(), "Thread CPU ms per step; Bullet with btAxisSweep3 (the paper's broad phase):");
  REQUIRE(title != chapter.end());
  int rows = 0;
  for (auto it = title + 4; it != chapter.end() && it->rfind("| ", 0) == 0; ++it, ++rows) {
    const auto cells = table_cells(*it);
    REQUIRE(cells.size() == 7);
    std::string n;
    for (const char c : cells[0])
      if (std::isdigit(static_cast<unsigned char>(c)))
        n += c;
    // Columns: N, full, low, spheres7, sphere, statistical, statistical (sap); each cell starts with
    // the figure, three significant digits.
    const std::vector<std::pair<std::string, std::string>> columns{
        {"full", "sap"}, {"low", "sap"}, {"sphere", "sap"}, {"statistical", "auto"}, {"statistical-sap", "sap"}};
    const std::vector<std::size_t> index{1, 2, 4, 5, 6};
    for (std::size_t k = 0; k < columns.size(); ++k) {
      const std::string cell = cells[index[k]].substr(1);
      if (cell.empty() || cell.rfind(" ", 0) == 0 || cell.rfind("skipped", 0) == 0)
        continue;
      const Row r = find_row(bench, {{"method", columns[k].first}, {"n", n}, {"broadphase", columns[k].second}}, file);
      const std::string want = sig(number(r, "cpu_ms"), 3);
      CHECK_MESSAGE(cell.rfind(want + " ", 0) == 0, "tools/bench/README.md, N = " << n << ", " << columns[k].first
                                                                                << ": should start with " << want
                                                                                << ": " << *it);
    }
  }
  CHECK(rows == 5);
}

TEST_CASE("docs: the firmware's footprint table is examples/images/footprint.csv")
{
  const auto chapter = lines_of(read_text("examples/firmware/README.md"));
  const std::string file = "examples/images/footprint.csv";
  const auto rows = read_csv(file);
  REQUIRE(rows.size() >= 6);
  for (const Row& r : rows) {
    const auto b = [&](const char* column) { return std::llround(number(r, column)); };
    // The row examples/firmware/footprint.cmake prints for this variant.
    const std::string row = "| `" + r.at("variant") + "` | " + kib(b("code_bytes")) + " | " + kib(b("tables_bytes")) +
                            " | " + kib(b("flash_bytes")) + " | " + kib(b("world3_bytes")) + " | " +
                            kib(b("world2_bytes")) + " | " + std::to_string(b("other_bytes")) + " B | " +
                            std::to_string(b("stack_bytes")) + " B | " + kib(b("ram_bytes")) + " | " +
                            std::to_string(b("world3_per_body")) + " B | " + std::to_string(b("world2_per_body")) +
                            " B |";
    CHECK_MESSAGE(contains_line(chapter, row), "examples/firmware/README.md should hold the row\n" << row);
  }
}

TEST_CASE("docs: the web page's size is examples/web/size.csv")
{
  const std::string file = "examples/web/size.csv";
  const auto rows = read_csv(file);
  const auto bytes = [&](const std::string& name) {
    return std::llround(number(find_row(rows, {{"file", name}}, file), "bytes"));
  };
  const long long html = bytes("index.html"), js = bytes("app.js"), wasm = bytes("statsim.wasm");
  const long long page = html + js + wasm;
  const std::string sizes = grouped(html) + " B + " + grouped(js) + " B + " + grouped(wasm) + " B = " + grouped(page) +
                            " B (the .wasm gzipped: " + grouped(bytes("statsim.wasm.gz")) + " B)";
  const std::string chapter = read_text("examples/web/README.md");
  CHECK_MESSAGE(chapter.find(sizes) != std::string::npos, "examples/web/README.md should say " << sizes);
  const std::string readme = read_text("README.md");
  const std::string page_kb = "a " + std::to_string((page + 500) / 1000) + " KB page";
  CHECK_MESSAGE(readme.find(page_kb) != std::string::npos, "README.md should say " << page_kb);
}

TEST_CASE("docs: the web page's step times are examples/web/step_ratio.csv")
{
  const std::string file = "examples/web/step_ratio.csv";
  const auto rows = read_csv(file);
  REQUIRE(rows.size() == 1);
  const Row& r = rows[0];
  // As bench.sh writes them: milliseconds to three decimals, the ratio to two.
  const std::string times = r.at("native_ms") + " / " + r.at("chromium_ms") + " (" + r.at("ratio") + "x)";
  const std::string chapter = read_text("examples/web/README.md");
  CHECK_MESSAGE(chapter.find("| " + times + ", same state hash |") != std::string::npos,
                "examples/web/README.md's table should say " << times);
  CHECK_MESSAGE(chapter.find("median ms per step: native " + r.at("native_ms") + ", chromium " + r.at("chromium_ms") +
                             ", ratio " + r.at("ratio")) != std::string::npos,
                "examples/web/README.md's run should end in the medians of " << file);
}

TEST_CASE("docs: tests/README.md names every file of tests/")
{
  const std::string list = read_text("tests/README.md");
  int files = 0;
  for (auto it = fs::recursive_directory_iterator("tests"); it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && (name == "meshes" || name == "corpus")) {
      it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file() || name == "README.md")
      continue;
    ++files;
    const std::string path = it->path().lexically_relative("tests").generic_string();
    const bool named = list.find("\n- `" + path + "` ") != std::string::npos ||
                       list.find("\n- `" + path + "`:") != std::string::npos;
    CHECK_MESSAGE(named,
                  "tests/README.md has no line \"- `" << path << "` ...\" for tests/" << path);
  }
  CHECK(files > 50);
}


TEST_CASE("docs: every chapter README under tools/ and examples/ has at most 300 lines")
{
  // The project's rule: a chapter holds today's content; what was measured before goes to the
  // dated LOG.md beside it.
  constexpr std::size_t max_lines = 300;
  std::vector<fs::path> chapters{"examples/README.md"};
  for (const fs::path dir : {"tools", "examples"})
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_directory() && fs::exists(entry.path() / "README.md"))
        chapters.push_back((entry.path() / "README.md").lexically_normal());
  std::sort(chapters.begin(), chapters.end());
  for (const auto& chapter : chapters) {
    const std::size_t n = lines_of(read_text(chapter)).size();
    CHECK_MESSAGE(n <= max_lines, chapter.generic_string() << " has " << n << " lines, more than " << max_lines
                                                            << ": move what is superseded to the LOG.md beside it");
  }
  CHECK(chapters.size() > 5);
}
