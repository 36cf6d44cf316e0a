#pragma once
// A small, strict command-line parser: declared options only, values checked, errors are
// UsageError (exit 2).

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace febemesh::cli {

class Args {
 public:
  /// `flags`: options without a value (e.g. "--quiet"); `valued`: options taking one value
  /// (e.g. "-o", "--level"). "--name=value" is accepted too.
  Args(const std::vector<std::string>& argv, std::set<std::string> flags, std::set<std::string> valued);

  bool has(const std::string& opt) const;
  std::optional<std::string> value(const std::string& opt) const;
  std::string value_or(const std::string& opt, const std::string& fallback) const;
  /// Integer value within [lo, hi], or fallback when absent; UsageError otherwise.
  int int_or(const std::string& opt, int fallback, int lo, int hi) const;
  /// Real value within [lo, hi], or fallback when absent.
  double real_or(const std::string& opt, double fallback, double lo, double hi) const;
  /// Value among `choices`, or fallback.
  std::string choice_or(const std::string& opt, const std::string& fallback,
                        const std::vector<std::string>& choices) const;
  const std::vector<std::string>& positional() const { return positional_; }
  /// Exactly n positionals, named for the error message.
  void expect_positional(const std::vector<std::string>& names) const;

 private:
  std::set<std::string> flags_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
};

}  // namespace febemesh::cli
