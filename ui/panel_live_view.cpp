// Live view: the working frame with the detector's overlays. Accepted markers in green with corner 0 marked and
// their id; rejected candidates in the colour of the stage that dropped them; the ledger's hovered row in
// yellow. Left-click selects a candidate for the inspector; with the region tool on, a left-drag marks the
// rectangle for "Why not detected?". With a scene loaded and "Media" on, the frame is the workbench's composite
// (the scene's media drawn on it); a click on a web card opens its URL in the system's browser. From "Labels..."
// each tracked marker's pose can be drawn: its axes, the paper's cube and the other solution of the ambiguity.
//
// Labels ("12 ARUCO_ORIGINAL") are placed by ui/label_layout.hpp: off each other, the markers' corners and the
// media, with a leader line when they had to move; those that find no room are counted in the view's corner.
// Projected media stay on top of labels and outlines: after the overlays, the composite is drawn again over each
// media quad (the same pixels, so nothing else changes), as a projector would cover whatever is under it.
#include "pose/marker_pose.hpp"
#include "ui/label_layout.hpp"
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

namespace arwb::ui {

namespace {

struct LiveViewState : PanelState {
  bool dragging = false;
  ImVec2 drag_from{0, 0};
  std::string pressed_url;   // a web card under the mouse when the left button went down
  LabelCache labels;         // where each marker's label was, so it stays put while the marker does
};

// The labels' text size in pixels at scale 1 (the window's normal font).
constexpr float kLabelFontPx = 15.0f;

// A line of text on a dark box in the view's top-left corner (or its bottom-left): what the picture is.
void corner_tag(ImDrawList* dl, const ImageMapping& m, const std::string& text, bool bottom = false,
                ImU32 col = IM_COL32(255, 255, 255, 255)) {
  const float h = ImGui::GetTextLineHeight(), w = ImGui::CalcTextSize(text.c_str()).x;
  const float y = bottom ? m.max.y - 10 - h : m.min.y + 4;
  dl->AddRectFilled({m.min.x + 4, y}, {m.min.x + 10 + w, y + h + 4}, IM_COL32(0, 0, 0, 170), 3);
  dl->AddText({m.min.x + 7, y + 2}, col, text.c_str());
}

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
                  stage_colour(c.fate.stage, 0.5f), 0, 0, 1.0f * s);
    }
  }
}

void overlay_markers(Context& ctx, const ImageMapping& m, ImDrawList* dl) {
  for (const Marker& mk : ctx.frame->trace.markers) {
    draw_quad(dl, m, mk.corners, accepted_colour(), 2.5f * ctx.scale, true);
  }
}

LabelQuad screen_quad(const ImageMapping& m, const Quad& q) {
  LabelQuad out;
  for (size_t i = 0; i < 4; ++i) {
    const ImVec2 p = m.to_screen(q[i]);
    out[i] = {p.x, p.y};
  }
  return out;
}

LabelQuad screen_quad(const ImageMapping& m, const MediaQuad& q) {
  LabelQuad out;
  for (size_t i = 0; i < 4; ++i) {
    const ImVec2 p = m.to_screen(static_cast<float>(q.corners[i].x), static_cast<float>(q.corners[i].y));
    out[i] = {p.x, p.y};
  }
  return out;
}

// The markers' labels, laid out (label_layout.hpp) and drawn: a dark box with the text, a leader line to the
// marker when the label had to move away; "+N labels hidden" in the view's bottom-left corner. Fills
// ctx.view.labels for --stats.
void overlay_labels(Context& ctx, const ImageMapping& m, ImDrawList* dl, LiveViewState& st) {
  View& v = ctx.view;
  v.labels = {};
  const float s = ctx.scale;
  const std::vector<Marker>& markers = ctx.frame->trace.markers;
  if (!v.show_accepted || (!v.label_ids && !v.label_dict) || markers.empty()) {
    st.labels.clear();
    return;
  }
  ImFont* font = ImGui::GetFont();
  const float font_px = kLabelFontPx * s;
  const ImVec2 pad{3.0f * s, 1.0f * s};
  const LabelBox view{m.min.x, m.min.y, m.max.x, m.max.y};
  LabelLayoutInput in;
  in.bounds = view;
  in.gap = 2.0f * s;
  in.corner_margin = std::max(3.0f, 2.5f * s * 2.0f) + 1.0f * s;   // draw_quad's corner-0 mark, and a pixel
  // The selected marker's label first, then by id and dictionary: the same order every frame.
  std::vector<size_t> order;
  for (size_t i = 0; i < markers.size(); ++i) {
    if (quad_box(screen_quad(m, markers[i].corners)).overlaps(view)) order.push_back(i);
  }
  const FrameTrace& t = ctx.frame->trace;
  const int selected = v.selected_candidate >= 0 && v.selected_candidate < static_cast<int>(t.candidates.size())
                           ? t.candidates[static_cast<size_t>(v.selected_candidate)].marker
                           : -1;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const Marker& x = markers[a];
    const Marker& y = markers[b];
    const bool xs = static_cast<int>(a) == selected, ys = static_cast<int>(b) == selected;
    if (xs != ys) return xs;
    if (x.id != y.id) return x.id < y.id;
    if (x.dict != y.dict) return x.dict < y.dict;
    return a < b;
  });
  std::vector<std::string> texts, short_texts;
  for (size_t i : order) {
    const Marker& mk = markers[i];
    std::string text;
    if (v.label_ids) text = std::to_string(mk.id);
    if (v.label_dict) text += (text.empty() ? "" : " ") + mk.dict;
    const ImVec2 sz = font->CalcTextSizeA(font_px, FLT_MAX, 0, text.c_str());
    LabelRequest r;
    r.anchor = screen_quad(m, mk.corners);
    r.width = sz.x + pad.x * 2;
    r.height = sz.y + pad.y * 2;
    // Where "12 ARUCO_ORIGINAL" finds no room, "12" may.
    short_texts.push_back(v.label_ids && v.label_dict ? std::to_string(mk.id) : std::string());
    if (!short_texts.back().empty()) {
      r.short_width = font->CalcTextSizeA(font_px, FLT_MAX, 0, short_texts.back().c_str()).x + pad.x * 2;
    }
    r.key = std::hash<std::string>{}(mk.dict) * 1000003u + static_cast<uint64_t>(static_cast<uint32_t>(mk.id));
    in.labels.push_back(r);
    texts.push_back(std::move(text));
  }
  // The media on screen cover labels (cover_with_media), so labels keep off them.
  if (ctx.composite) {
    for (const Overlay& o : ctx.frame->overlays) in.obstacles.push_back(screen_quad(m, o.quad));
  }
  // Room for the "+N labels hidden" note, so it never covers a label.
  char note[48];
  std::snprintf(note, sizeof note, "+%zu labels hidden", markers.size());
  const ImVec2 note_size = font->CalcTextSizeA(font_px, FLT_MAX, 0, note);
  const LabelBox note_box{view.x0, view.y1 - note_size.y - pad.y * 4, view.x0 + note_size.x + pad.x * 4, view.y1};
  in.obstacles.push_back({{{note_box.x0, note_box.y0}, {note_box.x1, note_box.y0}, {note_box.x1, note_box.y1},
                           {note_box.x0, note_box.y1}}});

  const LabelLayout layout = layout_labels(in, &st.labels);
  const ImU32 ink = accepted_colour();
  for (size_t k = 0; k < layout.placements.size(); ++k) {
    const LabelPlacement& p = layout.placements[k];
    if (!p.placed) continue;
    if (p.leader) dl->AddLine({p.leader_from.x, p.leader_from.y}, {p.leader_to.x, p.leader_to.y}, ink, 1.5f * s);
    dl->AddRectFilled({p.box.x0, p.box.y0}, {p.box.x1, p.box.y1}, IM_COL32(0, 0, 0, 190), 2.0f * s);
    dl->AddText(font, font_px, {p.box.x0 + pad.x, p.box.y0 + pad.y}, ink,
                (p.short_form ? short_texts[k] : texts[k]).c_str());
    v.labels.leaders += p.leader;
    v.labels.shortened += p.short_form;
    v.labels.boxes.push_back({static_cast<int>(std::floor(p.box.x0)), static_cast<int>(std::floor(p.box.y0)),
                              static_cast<int>(std::ceil(p.box.x1)), static_cast<int>(std::ceil(p.box.y1))});
  }
  v.labels.drawn = layout.placed;
  v.labels.hidden = layout.hidden;
  // A check of the layout's promise, for --stats: pairs of drawn labels that overlap, labels on a corner.
  for (size_t a = 0; a < layout.placements.size(); ++a) {
    const LabelPlacement& p = layout.placements[a];
    if (!p.placed) continue;
    for (size_t b = a + 1; b < layout.placements.size(); ++b) {
      v.labels.overlaps += layout.placements[b].placed && p.box.overlaps(layout.placements[b].box);
    }
    for (const LabelRequest& r : in.labels) {
      for (const LabelPoint& c : r.anchor) {
        if (c.x > p.box.x0 && c.x < p.box.x1 && c.y > p.box.y0 && c.y < p.box.y1) ++v.labels.on_corners;
      }
    }
  }
  if (layout.hidden > 0) {
    std::snprintf(note, sizeof note, "+%d label%s hidden", layout.hidden, layout.hidden == 1 ? "" : "s");
    const ImVec2 at{note_box.x0 + pad.x * 2, note_box.y1 - note_size.y - pad.y * 2};
    const ImVec2 sz = font->CalcTextSizeA(font_px, FLT_MAX, 0, note);
    dl->AddRectFilled({note_box.x0, note_box.y0}, {at.x + sz.x + pad.x * 2, note_box.y1}, IM_COL32(0, 0, 0, 200));
    dl->AddText(font, font_px, at, IM_COL32(230, 230, 230, 255), note);
  }
}

// The media on top of everything drawn over the frame: each media quad of the composite drawn again, in place,
// a screen pixel larger all round so no outline or label peeks out at its anti-aliased edge.
void cover_with_media(const Context& ctx, const ImageMapping& m, ImDrawList* dl) {
  if (!ctx.composite) return;
  const cv::Mat& img = ctx.frame->image;
  const float w = static_cast<float>(img.cols), h = static_cast<float>(img.rows);
  for (const Overlay& o : ctx.frame->overlays) {
    const LabelQuad q = screen_quad(m, o.quad);
    const float cx = (q[0].x + q[1].x + q[2].x + q[3].x) * 0.25f, cy = (q[0].y + q[1].y + q[2].y + q[3].y) * 0.25f;
    ImVec2 p[4], uv[4];
    for (size_t i = 0; i < 4; ++i) {
      const float dx = q[i].x - cx, dy = q[i].y - cy;
      const float len = std::sqrt(dx * dx + dy * dy);
      p[i] = len > 0 ? ImVec2{q[i].x + dx / len, q[i].y + dy / len} : ImVec2{q[i].x, q[i].y};
      const cv::Point2f px = m.to_image(p[i]);   // pixel centres at integers, as the compositor draws them
      uv[i] = {(px.x + 0.5f) / w, (px.y + 0.5f) / h};
    }
    dl->AddImageQuad(ctx.composite, p[0], p[1], p[2], p[3], uv[0], uv[1], uv[2], uv[3]);
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
      dl->AddCircle(s, 4.0f * ctx.scale, IM_COL32(255, 255, 255, 220), 12, 1.5f * ctx.scale);
    }
  }
}

// Lines between projected points; a segment whose ends project far outside the image (a point behind the camera,
// or the lens model past its range) is left out rather than drawn across the view.
void draw_segments(const ImageMapping& m, ImDrawList* dl, const std::vector<cv::Point2d>& p,
                   std::initializer_list<std::pair<int, int>> edges, ImU32 colour, float thickness, cv::Size size) {
  const auto sane = [&](const cv::Point2d& q) {
    return std::isfinite(q.x) && std::isfinite(q.y) && std::abs(q.x) < 4.0 * size.width + 1000 &&
           std::abs(q.y) < 4.0 * size.height + 1000;
  };
  for (const auto& [a, b] : edges) {
    const cv::Point2d& pa = p[static_cast<size_t>(a)];
    const cv::Point2d& pb = p[static_cast<size_t>(b)];
    if (!sane(pa) || !sane(pb)) continue;
    dl->AddLine(m.to_screen(cv::Point2f(pa)), m.to_screen(cv::Point2f(pb)), colour, thickness);
  }
}

// Each tracked marker's pose as 3D: the axes, the paper's cube standing on the marker (its base the marker, its
// top one side towards the camera) and, when asked, the other solution's cube, each labelled with its error. All
// are projected through the camera the poses were computed with, lens distortion included, so they sit on the
// marker where the image is bent. "assumed camera" is said on the view when there was no calibration.
void overlay_pose(Context& ctx, const ImageMapping& m, ImDrawList* dl) {
  View& v = ctx.view;
  v.pose_drawn = 0;
  if (!v.show_axes && !v.show_cube && !v.show_alternative) return;
  const Frame& f = *ctx.frame;
  const double L = f.pose_marker_side, h = L / 2;
  const std::vector<cv::Point3d> cube{{-h, h, 0}, {h, h, 0}, {h, -h, 0}, {-h, -h, 0},
                                      {-h, h, L}, {h, h, L}, {h, -h, L}, {-h, -h, L}};
  const std::vector<cv::Point3d> axes{{0, 0, 0}, {L, 0, 0}, {0, L, 0}, {0, 0, L}};
  const auto edges = {std::pair{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4},
                      {0, 4},          {1, 5}, {2, 6}, {3, 7}};
  const float t = 2.0f * ctx.scale;
  const cv::Size size = f.image.size();
  bool any = false;
  for (const TrackedMarker& tm : f.tracks) {
    if (!tm.pose) continue;
    const MarkerPose& p = *tm.pose;
    any = true;
    ++v.pose_drawn;
    const auto label = [&](const PoseSolution& s, ImU32 colour, const char* what) {
      const std::vector<cv::Point2d> top = project_marker_points({{0, 0, L}}, s, f.pose_camera);
      if (top.empty() || !std::isfinite(top[0].x) || !std::isfinite(top[0].y)) return;
      char text[64];
      std::snprintf(text, sizeof text, "%s %.2f px", what, s.error_px);
      dl->AddText(m.to_screen(cv::Point2f(top[0])), colour, text);
    };
    if (v.show_alternative) {
      const ImU32 alt = IM_COL32(255, 150, 40, 200);
      draw_segments(m, dl, project_marker_points(cube, p.alternative, f.pose_camera), edges, alt, 1.5f * ctx.scale, size);
      label(p.alternative, alt, "other");
    }
    if (v.show_cube) {
      // Amber when the view is ambiguous (the other solution explains the corners almost as well).
      const ImU32 col = p.ambiguity >= 0.3 ? IM_COL32(255, 220, 60, 255) : IM_COL32(80, 220, 255, 255);
      draw_segments(m, dl, project_marker_points(cube, p.pose, f.pose_camera), edges, col, t, size);
      label(p.pose, col, p.chosen_by_previous ? "kept" : "used");
    }
    if (v.show_axes) {
      const std::vector<cv::Point2d> a = project_marker_points(axes, p.pose, f.pose_camera);
      draw_segments(m, dl, a, {{0, 1}}, IM_COL32(255, 60, 60, 255), t, size);
      draw_segments(m, dl, a, {{0, 2}}, IM_COL32(60, 255, 60, 255), t, size);
      draw_segments(m, dl, a, {{0, 3}}, IM_COL32(80, 120, 255, 255), t, size);
    }
  }
  if (any && f.pose_camera.assumed) {
    corner_tag(dl, m, "poses with an assumed camera (no calibration loaded)", true, IM_COL32(255, 220, 60, 255));
  }
}

// The calibration board as the worker found it on this frame: its corners joined in their order (the line runs
// row by row, so a board found turned shows at once), the first corner marked, the outline of a full board, all
// green when the frame was kept as a view and orange otherwise, with the reason above the board. m shows the
// frame the search judged (s.searched); `behind`: not the newest frame, which is said at the top left.
void overlay_board(Context& ctx, const ImageMapping& m, ImDrawList* dl, bool behind) {
  const CalibrationSnapshot& s = *ctx.frame->calibration;
  const BoardDetection& d = s.detection;
  const bool found = d.found && !d.corners.empty();
  if (behind || !found) {
    const std::string none = "no " + s.board.describe() + " in view";
    const std::string text = !behind ? none : "board search: " + s.frame_name + (found ? " (behind the camera)" : ": " + none);
    corner_tag(dl, m, text);
    if (!found) return;
  }
  const ImU32 col = s.verdict.keep ? IM_COL32(80, 220, 100, 255) : IM_COL32(255, 160, 40, 255);
  const float t = 1.5f * ctx.scale;
  const int cols = s.board.inner_corners().width;
  const size_t n = d.corners.size();
  for (size_t i = 0; i + 1 < n; ++i) {
    // Within a row, and from a row's end to the next row's start (a chessboard's all-corners order), fading.
    const bool row_jump = d.ids.empty() && cols > 0 && (i + 1) % size_t(cols) == 0;
    dl->AddLine(m.to_screen(d.corners[i]), m.to_screen(d.corners[i + 1]),
                row_jump ? IM_COL32(255, 255, 255, 90) : col, row_jump ? 1.0f * ctx.scale : t);
  }
  for (const cv::Point2f& p : d.corners) dl->AddCircle(m.to_screen(p), 3.0f * ctx.scale, col, 10, t);
  const ImVec2 first = m.to_screen(d.corners[0]);
  const float r = 5 * ctx.scale;
  dl->AddRectFilled({first.x - r, first.y - r}, {first.x + r, first.y + r}, col);
  if (d.ids.empty() && cols > 0 && n >= size_t(cols) * 2 && n % size_t(cols) == 0) {
    const ImVec2 q[4] = {m.to_screen(d.corners[0]), m.to_screen(d.corners[size_t(cols) - 1]),
                         m.to_screen(d.corners[n - 1]), m.to_screen(d.corners[n - size_t(cols)])};
    dl->AddPolyline(q, 4, col, ImDrawFlags_Closed, 2.5f * ctx.scale);
  }
  float top = 1e9f, left = 1e9f;
  for (const cv::Point2f& p : d.corners) {
    const ImVec2 sp = m.to_screen(p);
    top = std::min(top, sp.y);
    left = std::min(left, sp.x);
  }
  const std::string text = s.verdict.keep ? "kept as view " + std::to_string(s.views.size()) : s.verdict.reason;
  const ImVec2 ts = ImGui::CalcTextSize(text.c_str());
  // Above the board, kept inside the view (a long reason on a board at the right edge ran off it).
  const ImVec2 at{std::max(std::min(left, m.max.x - ts.x - 5), m.min.x + 2), std::max(top - ts.y - 8 * ctx.scale,
                                                                                 m.min.y + (behind ? ts.y + 10 : 2))};
  dl->AddRectFilled({at.x - 3, at.y - 2}, {at.x + ts.x + 3, at.y + ts.y + 2}, IM_COL32(0, 0, 0, 170), 3);
  dl->AddText(at, col, text.c_str());
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
  flow(button_width("Labels..."));
  if (ImGui::Button("Labels...")) ImGui::OpenPopup("labels");
  if (ImGui::BeginPopup("labels")) {
    // Per kind, what the live view draws (also --actions labels=ids,dict,rejected,truth,peers / all / none).
    ImGui::Checkbox("Marker ids", &v.label_ids);
    ImGui::Checkbox("Dictionary names", &v.label_dict);
    ImGui::Checkbox("Rejected candidates", &v.show_rejected);
    ImGui::Checkbox("Truth (synthetic source)", &v.show_truth);
    ImGui::Checkbox("Peer: OpenCV aruco", &v.show_peer_opencv);
    ImGui::Checkbox("Peer: AprilTag", &v.show_peer_apriltag);
    // Each marker's pose in 3D (also --actions pose=axes,cube,alternative / all / none). In this popup rather than
    // a button of its own, so the toolbar keeps its width and the image its room.
    ImGui::Separator();
    ImGui::TextUnformatted("Pose in 3D");
    ImGui::Checkbox("Axes (x red, y green, z blue)", &v.show_axes);
    ImGui::Checkbox("Cube (the paper's, on the marker)", &v.show_cube);
    ImGui::Checkbox("The other solution's cube, with both errors", &v.show_alternative);
    ImGui::TextDisabled("A marker seen nearly from the front fits two poses;\nthe Pose panel shows how close they are.");
    if (ImGui::Button("Pose panel")) v.show(Panel::pose);
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
  if (ImGui::Button("Snapshot")) ctx.request(Snapshot{});
  flow(button_width("Fit"));
  if (ImGui::Button("Fit")) v.image.fit = true;
}

// "detect 0.71 ms", and in video mode which search the frame had (search_regions): "detect 0.40 ms, 2 regions".
void detect_part(const Frame& f, char* out, size_t n) {
  const SearchRecord& s = f.trace.search;
  if (f.trace.level == TraceLevel::off || s.whole)
    std::snprintf(out, n, "detect %.2f ms", f.detect_ms);
  else
    std::snprintf(out, n, "detect %.2f ms, %zu region%s %dx", f.detect_ms, s.regions.size(),
                  s.regions.size() == 1 ? "" : "s", s.factor);
}

void status_line(Context& ctx, const ImageMapping& m) {
  const Frame& f = *ctx.frame;
  const int x = static_cast<int>(std::lround(m.mouse_px.x)), y = static_cast<int>(std::lround(m.mouse_px.y));
  const FrameTrace& t = f.trace;
  int accepted = static_cast<int>(t.markers.size());
  // In parts that wrap (flow) in a narrow region; draw_live_view leaves room for status_lines() lines.
  char part[96];
  std::snprintf(part, sizeof part, "%s  %dx%d  %.0f%%", frame_label(f).c_str(), f.image.cols, f.image.rows,
                static_cast<double>(m.zoom) * 100.0);
  ImGui::TextUnformatted(part);
  std::snprintf(part, sizeof part, "%d markers, %zu candidates", accepted, t.candidates.size());
  flow(text_width(part));
  ImGui::TextUnformatted(part);
  detect_part(f, part, sizeof part);
  flow(text_width(part));
  ImGui::TextUnformatted(part);
  if (m.hovered && x >= 0 && y >= 0 && x < f.image.cols && y < f.image.rows) {
    const cv::Vec3b bgr = f.image.at<cv::Vec3b>(y, x);
    std::snprintf(part, sizeof part, "(%d, %d) RGB %d %d %d", x, y, bgr[2], bgr[1], bgr[0]);
    flow(text_width(part));
    ImGui::TextUnformatted(part);
    const int k = t.search_factor();  // the binary image is the decimated search's
    if (const StageRecord* th = t.stage(Stage::adaptive_threshold);
        th && !th->image.empty() && th->image.cols == f.image.cols / k && y / k < th->image.rows &&
        x / k < th->image.cols) {
      std::snprintf(part, sizeof part, "threshold %s",
                    th->image.at<uint8_t>(y / k, x / k) ? "foreground" : "background");
      flow(text_width(part));
      ImGui::TextUnformatted(part);
    }
  }
}

}  // namespace

void draw_live_view(Context& ctx) {
  LiveViewState& st = panel_state<LiveViewState>(ctx.view, Panel::live_view);
  if (ctx.view.presentation) {
    // In front of a class the picture matters, not the switches: they wait behind one button.
    if (ImGui::Button("Overlays...")) ImGui::OpenPopup("toolbar");
    if (ImGui::BeginPopup("toolbar")) {
      toolbar(ctx);
      ImGui::EndPopup();
    }
  } else {
    toolbar(ctx);
  }
  if (waiting_for_frame(ctx)) return;
  const Frame& f = *ctx.frame;
  ImVec2 avail = ImGui::GetContentRegionAvail();
  // Room for the status line's parts, on one line or wrapped (status_line).
  // The lines status_line's three parts take when they wrap as flow() wraps them (the zoom at its widest).
  float lines = 1, x = 0;
  char parts[3][96];
  std::snprintf(parts[0], sizeof parts[0], "%s  %dx%d  0000%%", frame_label(f).c_str(), f.image.cols, f.image.rows);
  std::snprintf(parts[1], sizeof parts[1], "%zu markers, %zu candidates", f.trace.markers.size(), f.trace.candidates.size());
  detect_part(f, parts[2], sizeof parts[2]);
  for (const char* part : parts) {
    const float w = text_width(part);
    if (x > 0 && x + ImGui::GetStyle().ItemSpacing.x + w > avail.x) {
      ++lines;
      x = w;
    } else {
      x += (x > 0 ? ImGui::GetStyle().ItemSpacing.x : 0) + w;
    }
  }
  avail.y -= ImGui::GetTextLineHeightWithSpacing() * lines;
  // Undistorted with a calibration (the Calibrate panel's toggle): a picture of other pixel coordinates, so nothing
  // found on the frame is drawn over it.
  if (ctx.settings.calibration.undistort && !f.undistorted.empty()) {
    const ImageMapping m = image_view(ctx, "live", "undistorted", f.undistorted, f.index, ctx.view.image, avail);
    ImDrawList* dl = ImGui::GetWindowDrawList();
    corner_tag(dl, m, "undistorted with " + f.undistorted_by);
    status_line(ctx, m);
    return;
  }
  // While calibrating, the view shows the frame the board search judged last, with the corners where they were
  // found: the search runs behind the frames (a frame without a board can take OpenCV a second), and corners
  // drawn on a newer frame land where the board no longer is. Nothing found on the newer frame is drawn over it.
  if (const CalibrationSnapshot* s = f.calibration.get(); s && !s->searched.empty()) {
    const ImageMapping m = image_view(ctx, "live", "board", s->searched, uint64_t(s->frames), ctx.view.image, avail);
    ImDrawList* dl = ImGui::GetWindowDrawList();
    dl->PushClipRect(m.min, m.max, true);
    overlay_board(ctx, m, dl, s->frame_name != f.calibration_name);
    dl->PopClipRect();
    status_line(ctx, m);
    return;
  }
  // The composite has the frame's size and pixel coordinates: everything drawn over it stays where it was.
  const ImageMapping m = image_view(ctx, "live", "frame", f.image, f.index, ctx.view.image, avail, ctx.composite);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(m.min, m.max, true);
  // While calibrating, the board's hundreds of rejected squares would hide it.
  if (f.calibration) corner_tag(dl, m, "looking for the board...");   // nothing judged yet: judged, shown above
  else overlay_candidates(ctx, m, dl);
  overlay_peers(ctx, m, dl);
  if (ctx.view.show_accepted) overlay_markers(ctx, m, dl);
  if (ctx.view.show_truth) overlay_truth(ctx, m, dl);
  overlay_labels(ctx, m, dl, st);
  cover_with_media(ctx, m, dl);
  overlay_pose(ctx, m, dl);
  const FrameTrace& t = f.trace;
  for (int idx : {ctx.view.selected_candidate, ctx.view.hovered_candidate}) {
    if (idx < 0 || idx >= static_cast<int>(t.candidates.size())) continue;
    const CandidateRecord& c = t.candidates[static_cast<size_t>(idx)];
    const ImU32 col = idx == ctx.view.hovered_candidate ? IM_COL32(255, 255, 0, 255) : IM_COL32(255, 255, 255, 255);
    if (c.has_quad) {
      draw_quad(dl, m, c.quad, col, 3.0f * ctx.scale, true);
    } else {
      dl->AddRect(m.to_screen(static_cast<float>(c.bbox.x), static_cast<float>(c.bbox.y)),
                  m.to_screen(static_cast<float>(c.bbox.br().x), static_cast<float>(c.bbox.br().y)), col, 0, 0,
                  3.0f * ctx.scale);
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
      dl->AddRect(m.to_screen(x0, y0), m.to_screen(x1, y1), IM_COL32(255, 255, 255, 255), 0, 0, 2.0f * ctx.scale);
      if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        st.dragging = false;
        if (x1 - x0 >= 2 && y1 - y0 >= 2) {
          ctx.view.region = {x0, y0, x1 - x0, y1 - y0};
          ctx.view.has_region = true;
          ctx.view.show(Panel::why);
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
      if (hit >= 0) ctx.view.show(Panel::inspector);
    }
  }
  if (!st.pressed_url.empty() && ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
    const float drag = io.MouseDragMaxDistanceSqr[ImGuiMouseButton_Left];
    const float threshold = io.MouseDragThreshold;
    if (!ctx.view.region_tool && hovered_web >= 0 && drag < threshold * threshold &&
        f.overlays[static_cast<size_t>(hovered_web)].media.url == st.pressed_url) {
      ctx.request(OpenUrl{st.pressed_url});
    }
    st.pressed_url.clear();
  }
  if (ctx.view.has_region) {
    const cv::Rect2f& r = ctx.view.region;
    dl->AddRect(m.to_screen(r.x, r.y), m.to_screen(r.x + r.width, r.y + r.height), IM_COL32(255, 255, 255, 200), 0, 0,
                1.5f * ctx.scale);
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
