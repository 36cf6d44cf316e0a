// `febemesh mesh2d` as users and scripts call it (DESIGN.md contracts): the output folder's
// files and what they hold, the report's counts and timings, the same mesh.msh on any thread
// count, and the exit statuses: 1 for bad input (one message naming the file, no folder left
// behind), 2 for bad usage.

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include "core/read_msh.hpp"
#include "core/validate.hpp"
#include "scratch_dir.hpp"

namespace {

struct Run {
  int status = -1;
  std::string output;  ///< stdout and stderr
};

Run run(const std::string& args, const std::string& env = "") {
  const std::string cmd = env + (env.empty() ? "" : " ") + "'" + FEBEMESH_CLI + "' " + args + " 2>&1";
  Run r;
  FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  char buf[4096];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) r.output.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const std::string flange = std::string(FEBEMESH_SOURCE_DIR) + "/examples/flange.json";

}  // namespace

TEST_CASE("mesh2d writes mesh.msh, mesh.vtu and a report whose counts are the mesh's", "[cli][mesh2d]") {
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "outputs";
  const Run r = run("mesh2d '" + flange + "' -o '" + dir.string() + "' --level 6 --threads 1 --quiet");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output == dir.string() + "\n");  // --quiet: only the folder, on stdout (for scripts)
  for (const char* f : {"mesh.msh", "mesh.vtu", "report.json"}) CHECK(std::filesystem::file_size(dir / f) > 100);
  const febemesh::Mesh<2> m = febemesh::read_msh<2>(dir / "mesh.msh");
  CHECK(febemesh::is_valid(m));
  const auto rep = nlohmann::json::parse(read_text(dir / "report.json"));
  CHECK(rep["counts"]["fe_elements"] == m.solid.size());
  CHECK(rep["counts"]["be_elements"] == m.interface.size());
  CHECK(rep["counts"]["nodes"] == m.points.size());
  CHECK(rep["validation"]["valid"] == true);
  // The pipeline's stages and the CLI's own steps, each a time, none over the total.
  const auto& t = rep["timings_seconds"];
  for (const char* step : {"subdivide", "smoothing", "read", "fidelity", "validation", "write mesh.msh and mesh.vtu"}) {
    INFO(step);
    REQUIRE(t.contains(step));
    CHECK(t[step].get<double>() >= 0.0);
    CHECK(t[step].get<double>() <= t["total"].get<double>());
  }
}

TEST_CASE("mesh2d's report counts the stages whether or not it kept them for the figures", "[cli][mesh2d]") {
  // Without figures the trees and the complex are dropped as soon as they are used (memory);
  // the report counted them from the dropped copies: 1 leaf, 0 boundary quadrants.
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "counts";
  for (const char* figures : {"auto", "none"})
    REQUIRE(run("mesh2d '" + flange + "' -o '" + (dir / figures).string() + "' --level 6 --quiet --figures " + figures).status == 0);
  const auto kept = nlohmann::json::parse(read_text(dir / "auto" / "report.json"));
  const auto dropped = nlohmann::json::parse(read_text(dir / "none" / "report.json"));
  CHECK(std::filesystem::exists(dir / "auto" / "figures"));
  // The last figure: every element filled by its smallest angle, each counted once in the legend.
  const std::string angles = read_text(dir / "auto" / "figures" / "09-angles.svg");
  std::size_t counted = 0, bins = 0;
  for (std::size_t at = angles.find(" deg: "); at != std::string::npos; at = angles.find(" deg: ", at + 1), ++bins)
    counted += std::stoul(angles.substr(at + 6));
  CHECK(bins == 5);
  CHECK(counted == kept["counts"]["fe_elements"].get<std::size_t>());
  CHECK(kept["counts"] == dropped["counts"]);
  const auto& c = dropped["counts"];
  CHECK(c["quadrants_subdivided"].get<std::size_t>() > 100);
  CHECK(c["quadrants_balanced"].get<std::size_t>() >= c["quadrants_subdivided"].get<std::size_t>());
  CHECK(c["quadrants_final"].get<std::size_t>() >= c["quadrants_balanced"].get<std::size_t>());
  CHECK(c["interior_quadrants"].get<std::size_t>() > 0);
  // One boundary quadrant a free edge of the interior quadrants.
  CHECK(c["boundary_quadrants"] == dropped["boundary_quadrants"]["free_edges"]);
  CHECK(c["boundary_quadrants"].get<std::size_t>() > 0);
}

TEST_CASE("mesh2d's progress lines carry the seconds since the start, never decreasing", "[cli][mesh2d]") {
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "progress";
  const Run r = run("mesh2d '" + flange + "' -o '" + dir.string() + "' --level 6 --threads 1");
  INFO(r.output);
  REQUIRE(r.status == 0);
  const std::regex stamped(R"(^mesh2d: \[ *([0-9]+\.[0-9]) s\] \S.*$)");
  std::istringstream lines(r.output);
  int n = 0;
  double last = 0.0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("mesh2d: ", 0) != 0) continue;
    std::smatch m;
    REQUIRE(std::regex_match(line, m, stamped));
    CHECK(std::stod(m[1]) >= last);
    last = std::stod(m[1]);
    ++n;
  }
  CHECK(n >= 5);  // reading, the stages, writing
}

TEST_CASE("mesh2d gives the same mesh.msh on 1 and 2 threads", "[cli][mesh2d]") {
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "threads";
  for (const char* n : {"1", "2"})
    REQUIRE(run("mesh2d '" + flange + "' -o '" + (dir / n).string() + "' --level 7 --quiet --threads " + n).status == 0);
  const std::string one = read_text(dir / "1" / "mesh.msh"), two = read_text(dir / "2" / "mesh.msh");
  CHECK(one.size() > 10000);
  CHECK(one == two);
}

TEST_CASE("mesh2d gives the same mesh.msh with and without the huge-page restart", "[cli][mesh2d]") {
  // By default (and with FEBEMESH_HUGE_PAGES=1) the program starts itself again with
  // glibc.malloc.hugetlb=1, unless GLIBC_TUNABLES sets the tunable already: the same arguments,
  // the same mesh. With FEBEMESH_HUGE_PAGES=0 no restart; one malloc arena and an 8 MiB mmap
  // threshold either way, unless GLIBC_TUNABLES sets them.
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "hugepages";
  const std::string args = "mesh2d '" + flange + "' --level 6 --quiet -o '";
  REQUIRE(run(args + (dir / "default").string() + "'").status == 0);
  REQUIRE(run(args + (dir / "huge").string() + "'", "FEBEMESH_HUGE_PAGES=1").status == 0);
  REQUIRE(run(args + (dir / "small").string() + "'", "FEBEMESH_HUGE_PAGES=0").status == 0);
  REQUIRE(run(args + (dir / "preset").string() + "'", "FEBEMESH_HUGE_PAGES=1 GLIBC_TUNABLES=glibc.malloc.hugetlb=0").status == 0);
  REQUIRE(run(args + (dir / "arenas").string() + "'", "GLIBC_TUNABLES=glibc.malloc.arena_max=4").status == 0);
  // glibc's own mmap threshold instead of set_up_malloc's (own_mapping_bytes).
  REQUIRE(run(args + (dir / "mapped").string() + "'", "GLIBC_TUNABLES=glibc.malloc.mmap_threshold=131072").status == 0);
  const std::string a = read_text(dir / "default" / "mesh.msh");
  CHECK(a.size() > 10000);
  CHECK(a == read_text(dir / "huge" / "mesh.msh"));
  CHECK(a == read_text(dir / "small" / "mesh.msh"));
  CHECK(a == read_text(dir / "preset" / "mesh.msh"));
  CHECK(a == read_text(dir / "arenas" / "mesh.msh"));
  CHECK(a == read_text(dir / "mapped" / "mesh.msh"));
  const Run help = run("--help");
  CHECK(help.output.find("FEBEMESH_HUGE_PAGES") != std::string::npos);
  CHECK(help.output.find("glibc.malloc.mmap_threshold") != std::string::npos);
  // Started through the dynamic loader, /proc/self/exe is the loader: no restart then (it would
  // run the loader with the arguments).
  for (const char* loader : {"/lib64/ld-linux-x86-64.so.2", "/lib/ld-linux-aarch64.so.1"}) {
    if (!std::filesystem::exists(loader)) continue;
    const std::string cmd = std::string("FEBEMESH_HUGE_PAGES=1 ") + loader + " '" + FEBEMESH_CLI + "' " + args + (dir / "loader").string() + "' 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    REQUIRE(p != nullptr);
    char buf[4096];
    std::string out;
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    const int st = pclose(p);
    INFO(cmd << "\n" << out);
    CHECK((WIFEXITED(st) && WEXITSTATUS(st) == 0));
    CHECK(a == read_text(dir / "loader" / "mesh.msh"));
  }
}

TEST_CASE("mesh2d refuses bad input with exit 1, one message naming the file, and no folder", "[cli][mesh2d]") {
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "bad";
  for (const std::string& input : {std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim2/bad_inputs/malformed.json",
                                   std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim2/bad_inputs/open_chain.poly",
                                   std::string(FEBEMESH_SOURCE_DIR) + "/tests/dim2/bad_inputs/nan_path.svg",
                                   dir.string() + "-missing.json"}) {
    const Run r = run("mesh2d '" + input + "' -o '" + dir.string() + "' --quiet");
    INFO(input << "\n" << r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find("error: " + input) != std::string::npos);
    CHECK(r.output.find('\n') == r.output.size() - 1);  // one line
    CHECK(!std::filesystem::exists(dir));
  }
}

TEST_CASE("mesh2d refuses bad usage with exit 2 and points to --help", "[cli][mesh2d]") {
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "usage";
  const std::string in = "mesh2d '" + flange + "'";
  for (const std::string& args : {in, in + " -o '" + dir.string() + "' --bogus",
                                  in + " -o '" + dir.string() + "' --elements hex",
                                  in + " -o '" + dir.string() + "' --level 30",
                                  in + " -o '" + dir.string() + "' --threads 0"}) {
    const Run r = run(args);
    INFO(args << "\n" << r.output);
    CHECK(r.status == 2);
    CHECK(r.output.find("--help") != std::string::npos);
    CHECK(!std::filesystem::exists(dir));
  }
  const Run help = run("mesh2d --help");
  CHECK(help.status == 0);
  for (const char* opt : {"--level", "--elements", "--threads", "--binary", "exit status"})
    CHECK(help.output.find(opt) != std::string::npos);
}

TEST_CASE("mesh2d and mesh3d refuse a tree over --max-cells: the file, the reason and the flag", "[cli][mesh2d][mesh3d]") {
  // Refused by the refinement itself (flange at level 14: ~1.9 x 10^8 quadrants; the CLI's own
  // estimate before it lets the level through), and in 3D by --max-cells.
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "max_cells";
  const Run r2 = run("mesh2d '" + flange + "' -o '" + dir.string() + "' --level 14 --quiet");
  INFO(r2.output);
  CHECK(r2.status == 1);
  CHECK(r2.output.find("refused: " + flange + ": refinement would create about") != std::string::npos);
  CHECK(r2.output.find("--max-cells N sets the limit") != std::string::npos);
  CHECK(std::count(r2.output.begin(), r2.output.end(), '\n') == 1);  // one message
  CHECK_FALSE(std::filesystem::exists(dir));
  const std::string sphere = std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off";
  const Run r3 = run("mesh3d '" + sphere + "' -o '" + dir.string() + "' --level 4 --max-cells 1000 --quiet");
  INFO(r3.output);
  CHECK(r3.status == 1);
  CHECK(r3.output.find("refused: " + sphere + ": refinement would create about") != std::string::npos);
  CHECK(r3.output.find("more than max_leaves = 1000") != std::string::npos);
  CHECK(r3.output.find("--max-cells N sets the limit") != std::string::npos);
  CHECK(std::count(r3.output.begin(), r3.output.end(), '\n') == 1);
  CHECK_FALSE(std::filesystem::exists(dir));
  CHECK(run("mesh3d '" + sphere + "' -o '" + dir.string() + "' --max-cells 10 --quiet").status == 2);  // under 100
}

TEST_CASE("mesh2d --size: the quadrants' side instead of a level; the count follows it", "[cli][mesh2d][size]") {
  // The flange is 6 x 6 (the default root square 6.3 across): level 6's quadrant is 6.3 / 64.
  // Sizes between level 6's and level 7's give counts between theirs; level 6's own size gives
  // level 6's mesh.
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const auto dir = scratch.path() / "size";
  const auto mesh = [&](const std::string& name, const std::string& args) {
    const Run r = run("mesh2d '" + flange + "' -o '" + (dir / name).string() + "' --threads 1 --no-figures --quiet " + args);
    INFO(args << "\n" << r.output);
    REQUIRE(r.status == 0);
    return nlohmann::json::parse(read_text(dir / name / "report.json"));
  };
  const auto l6 = mesh("l6", "--level 6"), l7 = mesh("l7", "--level 7");
  char same[64];
  std::snprintf(same, sizeof same, "--size %.17g", 6.3 / 64);
  const auto s6 = mesh("s6", same);
  CHECK(s6["options"]["root_scale"].get<double>() == 1.0);
  CHECK(s6["options"]["level"].get<double>() == 6.0);
  CHECK(read_text(dir / "s6" / "mesh.msh") == read_text(dir / "l6" / "mesh.msh"));
  CHECK(l6["options"]["size"].is_null());
  const auto count = [](const nlohmann::json& j) { return j["counts"]["fe_elements"].get<long>(); };
  long last = count(l6);
  for (const auto& [name, share] : {std::pair{"s80", 0.8}, std::pair{"s60", 0.6}}) {  // level-7 quadrants 1.6x, 1.2x
    char arg[64];
    std::snprintf(arg, sizeof arg, "--size %.17g", share * 6.3 / 64);
    const auto j = mesh(name, arg);
    INFO(arg);
    CHECK(j["options"]["level"].get<double>() == 7.0);
    CHECK(j["options"]["root_scale"].get<double>() == Approx(2 * share).epsilon(1e-5));
    CHECK(count(j) > last);
    CHECK(count(j) < count(l7));
    last = count(j);
  }
  CHECK(run("mesh2d '" + flange + "' -o '" + (dir / "x").string() + "' --size 0.1 --level 6").status == 2);
  CHECK(run("mesh2d '" + flange + "' -o '" + (dir / "x").string() + "' --size -1").status == 2);
  CHECK_FALSE(std::filesystem::exists(dir / "x"));
}

TEST_CASE("mesh2d and mesh3d never replace a folder they did not write", "[cli][mesh2d][mesh3d]") {
  namespace fs = std::filesystem;
  const febemesh::test::ScratchDir scratch("mesh2d_cli");
  const fs::path& root = scratch.path();
  const fs::path mine = root / "work";
  fs::create_directories(mine);
  std::ofstream(mine / "thesis.tex") << "years of work";
  const std::string sphere = std::string(FEBEMESH_DATA_DIR) + "/3d/sphere966.off";
  for (const std::string& args : {"mesh2d '" + flange + "' --level 5", "mesh3d '" + sphere + "' --level 3"}) {
    const Run r = run(args + " -o '" + mine.string() + "' --quiet --threads 1");
    INFO(args << "\n" << r.output);
    CHECK(r.status == 1);
    CHECK(r.output.find("error: output folder " + mine.string()) != std::string::npos);
    CHECK(r.output.find("'thesis.tex'") != std::string::npos);
    CHECK(r.output.find('\n') == r.output.size() - 1);  // one line
    CHECK(read_text(mine / "thesis.tex") == "years of work");
    CHECK(std::distance(fs::directory_iterator(root), fs::directory_iterator()) == 1);  // nothing beside it
  }
  // A folder of its own is replaced by the next run (the marker says whose it is).
  const fs::path out = root / "out";
  REQUIRE(run("mesh2d '" + flange + "' -o '" + out.string() + "' --level 5 --quiet --no-figures").status == 0);
  CHECK(fs::exists(out / ".febemesh-output"));
  REQUIRE(run("mesh2d '" + flange + "' -o '" + out.string() + "' --level 6 --quiet --no-figures").status == 0);
  CHECK(fs::exists(out / "mesh.msh"));
}
