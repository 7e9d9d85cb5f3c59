// The Lab panel's clips for arwb lab --videos: the paper's own method, a person showing a marker to the camera in
// known conditions. The marker and the conditions are typed once; Record films the source into a lossless clip of
// the folder's clips/ and lists it in the folder's videos.csv when it stops, with the paper's protocol as a
// checklist beside it and the marker printed at its true size; a video playing can have its row saved with the
// span in which the marker is visible (the paper's F_Num). Drawn from the settings, the frame and Status::lab_clip;
// the window records and writes (ui/lab_requests.cpp).
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>

namespace arwb::ui {

namespace {

// The paper's protocol (section 5.1) with the conditions typed: what to make true before each clip.
std::array<std::string, 6> protocol(const lab::VideoRow& r) {
  char b[6][240];
  std::snprintf(b[0], sizeof b[0], "Marker %d printed at 100 %% (not \"fit to page\"); its black square measures %g mm",
                r.id, r.size_mm);
  std::snprintf(b[1], sizeof b[1], "The marker's centre %g m from the camera, measured", r.distance_m);
  std::snprintf(b[2], sizeof b[2], "About %g lx on the marker, measured facing the camera (a lux meter or app)", r.lux);
  std::snprintf(b[3], sizeof b[3], "Held by hand, naturally, by its white border: nothing on the black square");
  std::snprintf(b[4], sizeof b[4], "Turned in its plane through 360 degrees, then tilted about its x and y axes");
  std::snprintf(b[5], sizeof b[5], "In view, whole or in part, for the whole clip (or mark the span after)");
  return {b[0], b[1], b[2], b[3], b[4], b[5]};
}

// The marker and the conditions, shared by Record and a video's row.
void conditions(Context& ctx, lab::VideoRow& row) {
  const Frame* f = ctx.frame;
  if (f && !f->trace.markers.empty()) {
    if (ImGui::Button("Use the marker in view")) {
      row.id = f->trace.markers[0].id;
      row.dictionary = f->trace.markers[0].dict;
    }
  }
  const float w = 130 * ctx.scale;
  fit_item_width(w, "marker id");
  ImGui::InputInt("marker id", &row.id);
  row.id = std::max(0, row.id);
  fit_item_width(w, "size (mm)");
  ImGui::InputDouble("size (mm)", &row.size_mm, 1, 10, "%.1f");
  fit_item_width(w, "distance (m)");
  ImGui::InputDouble("distance (m)", &row.distance_m, 0.1, 0.5, "%.2f");
  fit_item_width(w, "light (lux)");
  ImGui::InputDouble("light (lux)", &row.lux, 50, 100, "%.0f");
  ImGui::TextDisabled("dictionary %s", row.dictionary.c_str());
}

// Record and Stop, the folder, the checklist and the printed marker.
void record_section(Context& ctx, const std::string& folder) {
  LabSettings& ls = ctx.settings.lab;
  const bool recording = ctx.status.lab_recording;
  const ClipSummary& c = ctx.status.lab_clip;
  char dir[1024];
  std::snprintf(dir, sizeof dir, "%s", folder.c_str());
  fit_item_width(260 * ctx.scale, "folder");
  ImGui::BeginDisabled(recording);
  if (ImGui::InputText("folder", dir, sizeof dir)) ls.record_dir = dir;
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Clips go into its clips/, and their rows into its videos.csv.");
  const std::array<std::string, 6> items = protocol(ls.clip);
  const int ticked = int(std::count(ls.protocol.begin(), ls.protocol.end(), true));
  char header[96];
  std::snprintf(header, sizeof header, "The paper's protocol (%d of %d ticked)###protocol", ticked, int(items.size()));
  if (ImGui::TreeNodeEx(header, ImGuiTreeNodeFlags_DefaultOpen)) {
    for (size_t i = 0; i < items.size(); ++i) {
      ImGui::PushID(int(i));
      ImGui::Checkbox("##tick", &ls.protocol[i]);
      ImGui::SameLine();
      ImGui::TextWrapped("%s", items[i].c_str());
      ImGui::PopID();
    }
    ImGui::TreePop();
  }
  if (ImGui::Button("Print the marker at true size")) ctx.request(PrintClipMarker{});
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("A PDF in the folder: the marker at the size typed, with a bar to check the printer kept it.");
  if (!recording) {
    if (ImGui::Button("Record")) ctx.request(RecordClip{});
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("The source's frames from now, as taken, into a lossless clip; Stop lists it in videos.csv.");
  } else {
    ImGui::PushStyleColor(ImGuiCol_Button, IM_COL32(180, 50, 45, 255));
    if (ImGui::Button("Stop")) ctx.request(StopClip{});
    ImGui::PopStyleColor();
  }
  if (c.path.empty()) return;
  char b[1280];
  std::snprintf(b, sizeof b, "%s %s: %lld frames, %.1f s%s", recording ? "recording" : "last clip", c.path.c_str(),
                (long long)c.frames, c.seconds, c.dropped > 0 ? ", some dropped (the disk was too slow)" : "");
  text_disabled_wrapped(b);
}

// A video playing: its span as a row of videos.csv (the paper's F_Num: the frames in which the marker is visible).
void span_section(Context& ctx) {
  const Frame* f = ctx.frame;
  lab::VideoRow& row = ctx.settings.lab.clip;
  ImGui::TextUnformatted("This video's row");
  const int at = f->source.position;
  if (ImGui::Button("Span starts here")) row.first_frame = at;
  flow(button_width("Span ends here"));
  if (ImGui::Button("Span ends here")) row.last_frame = at;
  flow(button_width("Whole clip"));
  if (ImGui::Button("Whole clip")) row.first_frame = row.last_frame = -1;
  char b[160];
  if (row.first_frame >= 0 && row.last_frame >= 0)
    std::snprintf(b, sizeof b, "the marker is in view in frames %lld to %lld (%lld frames)", (long long)row.first_frame,
                  (long long)row.last_frame, (long long)(row.last_frame - row.first_frame + 1));
  else if (row.first_frame >= 0 || row.last_frame >= 0)
    std::snprintf(b, sizeof b, "mark the span's %s too", row.first_frame >= 0 ? "end" : "start");
  else
    std::snprintf(b, sizeof b, "the marker is in view in the whole clip");
  ImGui::TextWrapped("%s", b);
  if (ImGui::Button("Save to videos.csv")) ctx.request(SaveClip{});
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("A row in videos.csv beside the clip (replacing this clip's row if there is one).");
}

}  // namespace

void draw_lab_clips(Context& ctx) {
  const Frame* f = ctx.frame;
  const bool recording = ctx.status.lab_recording;
  // A lab cell's frames are the run's own: there is nothing to film or mark in them.
  if (!recording && (!f || f->source.kind == SourceKind::lab)) return;
  // Open from the start while a clip is filmed or a video plays; a click opens it on a camera.
  const bool video = f && f->source.kind == SourceKind::video;
  if (!ImGui::CollapsingHeader("Clips for arwb lab --videos", video || recording ? ImGuiTreeNodeFlags_DefaultOpen : 0))
    return;
  conditions(ctx, ctx.settings.lab.clip);
  record_section(ctx, record_folder(ctx.settings.lab, ctx.status.config_dir));
  if (video && !recording) span_section(ctx);
}

}  // namespace arwb::ui
