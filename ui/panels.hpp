// The workbench's panels, one file each (ui/panel_<key>.cpp). Each draws the inside of the window it is given
// (a region of the workspace, ui/workspace.hpp, under a tab named by panel_title()) from ctx.frame (const) and
// its view state;
// actions go to ctx.requests. A panel that has nothing to show says why ("No candidate selected: click one in
// the ledger").
#pragma once

#include "ui/context.hpp"

namespace arwb::ui {

void draw_live_view(Context& ctx);    // frame + overlays, zoom/pan, pixel under cursor, region tool
void draw_pipeline(Context& ctx);     // stage thumbnails in order, one large with the live view's zoom/pan
void draw_candidates(Context& ctx);   // the ledger: every candidate and its fate, sortable, filterable
void draw_inspector(Context& ctx);    // the selected candidate: contour, quad, warp, histogram, bits, rotations
void draw_parameters(Context& ctx);   // the parameter table as sliders, reset, YAML presets
void draw_timings(Context& ctx);      // ms per stage, fps, history plot
void draw_dictionary(Context& ctx);   // markers of a dictionary, min distance, closest pairs
void draw_peers(Context& ctx);        // OpenCV aruco and AprilTag on the same frame
void draw_source(Context& ctx);       // source choice, playback, acquisition, synthetic source controls
void draw_tour(Context& ctx);         // the guided teaching tour
void draw_why(Context& ctx);          // "why isn't my marker detected?" report and sweep
void draw_log(Context& ctx);          // messages, warnings and errors
void draw_scene(Context& ctx);        // the scene in use: load, examples, mappings, markers in view
void draw_script(Context& ctx);       // the scene file's text: edit, save, error line marked
void draw_console(Context& ctx);      // the scene's print output, warnings and errors
void draw_calibrate(Context& ctx);    // the calibration coach: board, capture, checklist, coverage, the camera
void draw_calibration_views(Context& ctx);   // per-view errors (click drops), coverage and cross-validation maps
void draw_pose(Context& ctx);         // each tracked marker's pose: position, angles, ambiguity, errors over time
void draw_lab(Context& ctx);          // the recognition lab: plan, run, the grid filling in, a cell's frames
void draw_lab_clips(Context& ctx);    // its clips for arwb lab --videos: Record from the source, a video's span

// Draws panel p into the current window.
void draw_panel(Panel p, Context& ctx);

}  // namespace arwb::ui
