#include "cli/args.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "cli/command.hpp"

namespace febemesh::cli {
namespace {

/// x as the shortest text that reads back as x ("28", "0.5", "1e+30").
std::string shortest(double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

}  // namespace

Args::Args(const std::vector<std::string>& argv, std::set<std::string> flags, std::set<std::string> valued) {
  for (std::size_t i = 0; i < argv.size(); ++i) {
    std::string a = argv[i];
    if (a.size() > 1 && a[0] == '-' && !(a.size() > 1 && (std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.'))) {
      std::string name = a;
      std::optional<std::string> inline_value;
      if (auto eq = a.find('='); eq != std::string::npos && a.rfind("--", 0) == 0) {
        name = a.substr(0, eq);
        inline_value = a.substr(eq + 1);
      }
      if (flags.count(name)) {
        if (inline_value) throw UsageError("option " + name + " takes no value");
        flags_.insert(name);
      } else if (valued.count(name)) {
        if (inline_value) {
          values_[name] = *inline_value;
        } else {
          if (i + 1 >= argv.size()) throw UsageError("option " + name + " needs a value");
          values_[name] = argv[++i];
        }
      } else {
        throw UsageError("unknown option " + a);
      }
    } else {
      positional_.push_back(a);
    }
  }
}

bool Args::has(const std::string& opt) const { return flags_.count(opt) > 0 || values_.count(opt) > 0; }

std::optional<std::string> Args::value(const std::string& opt) const {
  auto it = values_.find(opt);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

std::string Args::value_or(const std::string& opt, const std::string& fallback) const {
  return value(opt).value_or(fallback);
}

int Args::int_or(const std::string& opt, int fallback, int lo, int hi) const {
  auto v = value(opt);
  if (!v) return fallback;
  errno = 0;
  char* end = nullptr;
  long x = std::strtol(v->c_str(), &end, 10);
  if (v->empty() || *end != '\0' || errno != 0 || x < lo || x > hi)
    throw UsageError("option " + opt + " expects an integer in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "], got '" + *v + "'");
  return static_cast<int>(x);
}

double Args::real_or(const std::string& opt, double fallback, double lo, double hi) const {
  auto v = value(opt);
  if (!v) return fallback;
  char* end = nullptr;
  double x = std::strtod(v->c_str(), &end);
  if (v->empty() || *end != '\0' || !std::isfinite(x) || x < lo || x > hi)
    throw UsageError("option " + opt + " expects a number in [" + shortest(lo) + ", " + shortest(hi) + "], got '" +
                     *v + "'");
  return x;
}

std::string Args::choice_or(const std::string& opt, const std::string& fallback,
                            const std::vector<std::string>& choices) const {
  auto v = value(opt);
  if (!v) return fallback;
  for (const auto& c : choices)
    if (c == *v) return c;
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
  throw UsageError("option " + opt + " expects one of " + list + ", got '" + *v + "'");
}

void Args::expect_positional(const std::vector<std::string>& names) const {
  if (positional_.size() < names.size()) throw UsageError("missing argument " + names[positional_.size()]);
  if (positional_.size() > names.size()) throw UsageError("unexpected argument '" + positional_[names.size()] + "'");
}

}  // namespace febemesh::cli
