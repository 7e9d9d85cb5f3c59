// Undo and redo of the detector's settings: the parameters and the dictionaries, one entry per completed edit
// (a slider drag is one entry, a preset loaded is one), each named for the status bar ("quad_fit.min_side_rate
// 0.1 -> 0.05", "preset fast.yml"). Pure logic: the window decides when an edit is complete and applies the
// states this hands back.
#pragma once

#include "detect/params.hpp"

#include <string>
#include <vector>

namespace arwb::ui {

// What an undo step restores.
struct DetectorState {
  DetectorParams params;
  std::vector<std::string> dictionaries;
  bool operator==(const DetectorState&) const = default;
};

// "adaptive_threshold.threshold_window_px 17 -> 21" for one parameter, "dictionaries ARUCO_ORIGINAL ->
// 6X6_250" for the dictionaries, "3 parameters" when several changed at once; "" when nothing differs.
std::string describe_change(const DetectorState& before, const DetectorState& after);

class SettingsHistory {
 public:
  // Records a completed edit from `before` to `after` named `name`; what could be redone is dropped. Nothing is
  // recorded when the two are equal. The oldest entries go beyond `kMax`.
  void record(const DetectorState& before, const DetectorState& after, const std::string& name);
  bool can_undo() const { return next_ > 0; }
  bool can_redo() const { return next_ < entries_.size(); }
  // The name of what undo / redo would do ("" when nothing).
  std::string undo_name() const { return can_undo() ? entries_[next_ - 1].name : std::string(); }
  std::string redo_name() const { return can_redo() ? entries_[next_].name : std::string(); }
  // Steps back (forth) and returns the state to apply; false when there is nothing to undo (redo).
  bool undo(DetectorState* state, std::string* name);
  bool redo(DetectorState* state, std::string* name);
  size_t size() const { return entries_.size(); }

  static constexpr size_t kMax = 200;

 private:
  struct Entry {
    DetectorState before, after;
    std::string name;
  };
  std::vector<Entry> entries_;
  size_t next_ = 0;   // entries_[next_ - 1] is what undo undoes
};

}  // namespace arwb::ui
