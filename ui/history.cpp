#include "ui/history.hpp"

#include "base/decimals.hpp"

namespace arwb::ui {

namespace {
std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s.empty() ? "(none)" : s;
}
}  // namespace

std::string describe_change(const DetectorState& before, const DetectorState& after) {
  std::string one;
  int changed = 0;
  for (const ParamInfo& info : param_table()) {
    const double a = get_param(before.params, info), b = get_param(after.params, info);
    if (a == b) continue;
    ++changed;
    const int d = param_decimals(info);
    one = std::string(info.stage) + "." + info.name + " " + decimals_text(a, d) + " -> " + decimals_text(b, d);
  }
  const bool dicts = before.dictionaries != after.dictionaries;
  const std::string dict_text = "dictionaries " + join(before.dictionaries) + " -> " + join(after.dictionaries);
  if (changed == 0) return dicts ? dict_text : std::string();
  std::string s = changed == 1 ? one : std::to_string(changed) + " parameters";
  if (dicts) s += ", " + dict_text;
  return s;
}

void SettingsHistory::record(const DetectorState& before, const DetectorState& after, const std::string& name) {
  if (before == after) return;
  entries_.resize(next_);
  entries_.push_back({before, after, name.empty() ? describe_change(before, after) : name});
  if (entries_.size() > kMax) entries_.erase(entries_.begin());
  next_ = entries_.size();
}

bool SettingsHistory::undo(DetectorState* state, std::string* name) {
  if (!can_undo()) return false;
  --next_;
  *state = entries_[next_].before;
  *name = entries_[next_].name;
  return true;
}

bool SettingsHistory::redo(DetectorState* state, std::string* name) {
  if (!can_redo()) return false;
  *state = entries_[next_].after;
  *name = entries_[next_].name;
  ++next_;
  return true;
}

}  // namespace arwb::ui
