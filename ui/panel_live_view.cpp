// Live view: the working frame with the detector's overlays. Accepted markers in green with corner 0 marked and
// their id; rejected candidates in the colour of the stage that dropped them; the ledger's hovered row in
// yellow. Left-click selects a candidate for the inspector; with the region tool on, a left-drag marks the
// rectangle for "Why not detected?". With a scene loaded and "Media" on, the frame is the workbench's composite
// (the scene's media drawn on it); a click on a web card opens its URL in the system's browser.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace arwb::ui {

namespace {

struct LiveViewState : PanelState {
  bool dragging = false;
  ImVec2 drag_from{0, 0};
  std::string pressed_url;   // a web card under the mouse when the left button went down
};

void overlay_candidates(Context& ctx, const ImageMapping& m, ImDrawList* dl) {
  const FrameTrace& t = ctx.frame->trace;
  const View& v = ctx.view;
  const float s = ctx.scale;
  for (size_t i = 0; i < t.candidates.size(); ++i) {
    const CandidateRecord& c = t.candidates[i];
    if (c.fate.stage == Stage::accepted) continue;
    if (!v.show_rejected || !v.show_rejected_stage[static_cast<size_t>(c.fate.stage)]) continue;
    // Contours rejected by size are many and tiny; draw them thin so the quads stand out.
    const ImU32 col = stage_colour(c.fate.stage, 0.85f);
    if (c.has_quad) {
      draw_quad(dl, m, c.quad, col, 1.5f * s);
    } else {
      dl->AddRect(m.to_screen(static_cast<float>(c.bbox.x) - 0.5f, static_cast<float>(c.bbox.y) - 0.5f),
                  m.to_screen(static_cast<float>(c.bbox.br().x) - 0.5f, static_cast<float>(c.bbox.br().y) - 0.5f),
                  stage_colour(c.fate.stage, 0.5f), 0, 0, 1.0f);
    }
  }
}

void overlay_markers(Context& ctx, const ImageMapping& m, ImDrawList* dl) {
  const float s = ctx.scale;
  for (const Marker& mk : ctx.frame->trace.markers) {
    draw_quad(dl, m, mk.corners, accepted_colour(), 2.5f * s, true);
    const cv::Point2f c = quad_centre(mk.corners);
    char label[96];
    std::snprintf(label, sizeof label, "%d %s", mk.id, mk.dict.c_str());
    const ImVec2 at = m.to_screen(c);
    const ImVec2 sz = ImGui::CalcTextSize(label);
    dl->AddRectFilled({at.x - sz.x * 0.5f - 3, at.y - sz.y * 0.5f - 1}, {at.x + sz.x * 0.5f + 3, at.y + sz.y * 0.5f + 1},
                      IM_COL32(0, 0, 0, 170));
    dl->AddText({at.x - sz.x * 0.5f, at.y - sz.y * 0.5f}, accepted_colour(), label);
  }
}

void overlay_peers(Context& ctx, const ImageMapping& m, ImDrawList* dl) {
  for (const PeerDetections& p : ctx.frame->peers) {
    const bool opencv = p.name == "opencv_aruco";
    if (opencv ? !ctx.view.show_peer_opencv : !ctx.view.show_peer_apriltag) continue;
    const ImU32 col = opencv ? IM_COL32(255, 120, 255, 255) : IM_COL32(80, 200, 255, 255);
    for (const Marker& mk : p.markers) {
      // Dashed look: corners only, so the peers' outlines do not hide arwb's.
      ImVec2 pts[4];
      for (int i = 0; i < 4; ++i) pts[i] = m.to_screen(mk.corners[static_cast<size_t>(i)]);
      for (int i = 0; i < 4; ++i) {
        const ImVec2 a = pts[i], b = pts[(i + 1) % 4];
        dl->AddLine(a, {a.x + (b.x - a.x) * 0.3f, a.y + (b.y - a.y) * 0.3f}, col, 2.0f * ctx.scale);
        dl->AddLine({b.x + (a.x - b.x) * 0.3f, b.y + (a.y - b.y) * 0.3f}, b, col, 2.0f * ctx.scale);
      }
    }
  }
}

void overlay_truth(Context& ctx, const ImageMapping& m, ImDrawList* dl) {
  for (const TruthMarker& tm : ctx.frame->truth) {
    for (const auto& p : tm.corners) {
      const ImVec2 s = m.to_screen(p);
      dl->AddCircle(s, 4.0f * ctx.scale, IM_COL32(255, 255, 255, 220), 12, 1.5f);
    }
  }
}

// The candidate under the mouse: the smallest quad (or bbox) that contains the point.
int candidate_at(const FrameTrace& t, cv::Point2f p) {
  int best = -1;
  double best_area = 1e30;
  for (size_t i = 0; i < t.candidates.size(); ++i) {
    const CandidateRecord& c = t.candidates[i];
    if (!c.has_quad) continue;
    std::vector<cv::Point2f> q(c.quad.begin(), c.quad.end());
    if (cv::pointPolygonTest(q, p, false) < 0) continue;
    const double area = std::abs(cv::contourArea(q));
    if (area < best_area) {
      best_area = area;
      best = static_cast<int>(i);
    }
  }
  return best;
}

// The overlay whose drawn quad is under image point `p`, topmost first (later overlays are drawn on top); -1 when
// none. Only while the media are on screen.
int overlay_at(const Context& ctx, cv::Point2f p, bool web_only) {
  return ctx.composite ? arwb::overlay_at(ctx.frame->overlays, {p.x, p.y}, web_only) : -1;
}

void outline_overlay(const ImageMapping& m, ImDrawList* dl, const Overlay& o, ImU32 colour, float thickness) {
  ImVec2 pts[4];
  for (size_t i = 0; i < 4; ++i) {
    pts[i] = m.to_screen(static_cast<float>(o.quad.corners[i].x), static_cast<float>(o.quad.corners[i].y));
  }
  dl->AddPolyline(pts, 4, colour, ImDrawFlags_Closed, thickness);
}

// The toolbar wraps in a narrow region (flow) rather than running past its edge.
void toolbar(Context& ctx) {
  View& v = ctx.view;
  ImGui::Checkbox("Markers", &v.show_accepted);
  flow(checkbox_width("Rejected"));
  ImGui::Checkbox("Rejected", &v.show_rejected);
  flow(button_width("Stages..."));
  if (ImGui::Button("Stages...")) ImGui::OpenPopup("stages");
  if (ImGui::BeginPopup("stages")) {
    for (int i = 0; i < kStageCount; ++i) {
      const Stage s = static_cast<Stage>(i);
      ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(s));
      bool on = v.show_rejected_stage[static_cast<size_t>(i)];
      const std::string name(stage_name(s));
      if (ImGui::Checkbox(name.c_str(), &on)) v.show_rejected_stage[static_cast<size_t>(i)] = on;
      ImGui::PopStyleColor();
    }
    ImGui::EndPopup();
  }
  flow(checkbox_width("Truth"));
  if (ctx.frame && !ctx.frame->truth.empty()) {
    ImGui::Checkbox("Truth", &v.show_truth);
    flow(checkbox_width("Media"));
  }
  ImGui::Checkbox("Media", &v.show_media);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip(ctx.frame && !ctx.frame->scene.file.empty()
                          ? "Draw the scene's media on the frame (images, videos, web and text cards)."
                          : "Draw the scene's media on the frame. No scene is loaded: see the Scene panel.");
  }
  flow(checkbox_width("Why? (drag)"));
  ImGui::Checkbox("Why? (drag)", &v.region_tool);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Drag a rectangle around a marker that is not detected: the 'Why not detected?' panel\n"
                      "lists every candidate there and where the pipeline dropped it.");
  }
  flow(checkbox_width("Freeze"));
  if (ImGui::Checkbox("Freeze", &ctx.settings.frozen)) {}
  flow(button_width("Snapshot"));
  if (ImGui::Button("Snapshot")) ctx.request(RequestKind::snapshot);
  flow(button_width("Fit"));
  if (ImGui::Button("Fit")) v.image.fit = true;
}

void status_line(Context& ctx, const ImageMapping& m) {
  const Frame& f = *ctx.frame;
  const int x = static_cast<int>(std::lround(m.mouse_px.x)), y = static_cast<int>(std::lround(m.mouse_px.y));
  const FrameTrace& t = f.trace;
  int accepted = static_cast<int>(t.markers.size());
  // In parts that wrap (flow) in a narrow region; draw_live_view leaves room for status_lines() lines.
  char part[96];
  std::snprintf(part, sizeof part, "frame %llu  %dx%d  %.0f%%", static_cast<unsigned long long>(f.index), f.image.cols,
                f.image.rows, static_cast<double>(m.zoom) * 100.0);
  ImGui::TextUnformatted(part);
  std::snprintf(part, sizeof part, "%d markers, %zu candidates", accepted, t.candidates.size());
  flow(text_width(part));
  ImGui::TextUnformatted(part);
  std::snprintf(part, sizeof part, "detect %.2f ms", f.detect_ms);
  flow(text_width(part));
  ImGui::TextUnformatted(part);
  if (m.hovered && x >= 0 && y >= 0 && x < f.image.cols && y < f.image.rows) {
    const cv::Vec3b bgr = f.image.at<cv::Vec3b>(y, x);
    std::snprintf(part, sizeof part, "(%d, %d) RGB %d %d %d", x, y, bgr[2], bgr[1], bgr[0]);
    flow(text_width(part));
    ImGui::TextUnformatted(part);
    if (const StageRecord* th = t.stage(Stage::adaptive_threshold); th && !th->image.empty() &&
                                                                     th->image.cols == f.image.cols) {
      std::snprintf(part, sizeof part, "threshold %s", th->image.at<uint8_t>(y, x) ? "foreground" : "background");
      flow(text_width(part));
      ImGui::TextUnformatted(part);
    }
  }
}

}  // namespace

void draw_live_view(Context& ctx) {
  LiveViewState& st = panel_state<LiveViewState>(ctx.view, Panel::live_view);
  toolbar(ctx);
  if (waiting_for_frame(ctx)) return;
  const Frame& f = *ctx.frame;
  ImVec2 avail = ImGui::GetContentRegionAvail();
  // Room for the status line's parts, on one line or wrapped (status_line).
  const float parts = text_width("frame 000000  0000x0000  000%") + text_width("00 markers, 0000 candidates") +
                      text_width("detect 00.00 ms") + ImGui::GetStyle().ItemSpacing.x * 2;
  const float lines = parts <= avail.x ? 1.0f : std::ceil(parts / std::max(avail.x, 1.0f)) + 1.0f;
  avail.y -= ImGui::GetTextLineHeightWithSpacing() * lines;
  // The composite has the frame's size and pixel coordinates: everything drawn over it stays where it was.
  const ImageMapping m = image_view(ctx, "live", "frame", f.image, f.index, ctx.view.image, avail, ctx.composite);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(m.min, m.max, true);
  overlay_candidates(ctx, m, dl);
  overlay_peers(ctx, m, dl);
  if (ctx.view.show_accepted) overlay_markers(ctx, m, dl);
  if (ctx.view.show_truth) overlay_truth(ctx, m, dl);
  const FrameTrace& t = f.trace;
  for (int idx : {ctx.view.selected_candidate, ctx.view.hovered_candidate}) {
    if (idx < 0 || idx >= static_cast<int>(t.candidates.size())) continue;
    const CandidateRecord& c = t.candidates[static_cast<size_t>(idx)];
    const ImU32 col = idx == ctx.view.hovered_candidate ? IM_COL32(255, 255, 0, 255) : IM_COL32(255, 255, 255, 255);
    if (c.has_quad) {
      draw_quad(dl, m, c.quad, col, 3.0f * ctx.scale, true);
    } else {
      dl->AddRect(m.to_screen(static_cast<float>(c.bbox.x), static_cast<float>(c.bbox.y)),
                  m.to_screen(static_cast<float>(c.bbox.br().x), static_cast<float>(c.bbox.br().y)), col, 0, 0, 3.0f);
    }
  }
  // The media under the mouse: a thin outline (a web card's in the link colour).
  const cv::Point2f mouse{m.mouse_px.x, m.mouse_px.y};
  const int hovered_overlay = m.hovered ? overlay_at(ctx, mouse, false) : -1;
  const int hovered_web = m.hovered && !ctx.view.region_tool ? overlay_at(ctx, mouse, true) : -1;
  if (hovered_overlay >= 0) {
    const Overlay& o = f.overlays[static_cast<size_t>(hovered_overlay)];
    outline_overlay(m, dl, o, IM_COL32(255, 255, 255, 150), 1.0f * ctx.scale);
  }
  if (hovered_web >= 0) {
    outline_overlay(m, dl, f.overlays[static_cast<size_t>(hovered_web)], IM_COL32(90, 170, 255, 255), 1.5f * ctx.scale);
  }
  // Region tool: left-drag a rectangle.
  ImGuiIO& io = ImGui::GetIO();
  if (ctx.view.region_tool) {
    if (m.hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
      st.dragging = true;
      st.drag_from = m.mouse_px;
    }
    if (st.dragging) {
      const cv::Point2f now = m.to_image(io.MousePos);
      const float x0 = std::min(st.drag_from.x, now.x), y0 = std::min(st.drag_from.y, now.y);
      const float x1 = std::max(st.drag_from.x, now.x), y1 = std::max(st.drag_from.y, now.y);
      dl->AddRect(m.to_screen(x0, y0), m.to_screen(x1, y1), IM_COL32(255, 255, 255, 255), 0, 0, 2.0f);
      if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        st.dragging = false;
        if (x1 - x0 >= 2 && y1 - y0 >= 2) {
          ctx.view.region = {x0, y0, x1 - x0, y1 - y0};
          ctx.view.has_region = true;
          ctx.view.open[static_cast<size_t>(Panel::why)] = true;
        }
      }
    }
  } else if (m.hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    if (hovered_web >= 0) {
      // A web card: opened when the button comes up without a drag, over the same card.
      st.pressed_url = f.overlays[static_cast<size_t>(hovered_web)].media.url;
    } else {
      st.pressed_url.clear();
      const int hit = candidate_at(t, {m.mouse_px.x, m.mouse_px.y});
      ctx.view.selected_candidate = hit;
      if (hit >= 0) ctx.view.open[static_cast<size_t>(Panel::inspector)] = true;
    }
  }
  if (!st.pressed_url.empty() && ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
    const float drag = io.MouseDragMaxDistanceSqr[ImGuiMouseButton_Left];
    const float threshold = io.MouseDragThreshold;
    if (!ctx.view.region_tool && hovered_web >= 0 && drag < threshold * threshold &&
        f.overlays[static_cast<size_t>(hovered_web)].media.url == st.pressed_url) {
      ctx.request(RequestKind::open_url, st.pressed_url);
    }
    st.pressed_url.clear();
  }
  if (ctx.view.has_region) {
    const cv::Rect2f& r = ctx.view.region;
    dl->AddRect(m.to_screen(r.x, r.y), m.to_screen(r.x + r.width, r.y + r.height), IM_COL32(255, 255, 255, 200), 0, 0,
                1.5f);
  }
  dl->PopClipRect();
  if (hovered_web >= 0) {
    ImGui::SetMouseCursor(ImGuiMouseCursor_Hand);
    ImGui::SetTooltip("Open %s", f.overlays[static_cast<size_t>(hovered_web)].media.url.c_str());
  } else if (m.hovered && !ctx.view.region_tool) {
    const int hit = candidate_at(t, {m.mouse_px.x, m.mouse_px.y});
    if (hit >= 0) ImGui::SetTooltip("%s", candidate_line(t, hit).c_str());
  }
  status_line(ctx, m);
}

}  // namespace arwb::ui
