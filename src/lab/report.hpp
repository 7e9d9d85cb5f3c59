// The lab's results as pictures (issue 14): recall curves and per-detector heatmaps as PNG, and one report.pdf
// with a title page and the same plots, drawn with PLplot's cairo devices (pngcairo, pdfcairo).
#pragma once

#include "lab/run.hpp"
#include "base/result.hpp"

#include <string>
#include <vector>

namespace arwb::lab {

// The PNGs' size in pixels, and report.pdf's page in points (A4 landscape).
inline constexpr int kPlotWidthPx = 800, kPlotHeightPx = 600;
inline constexpr int kReportPageWidthPt = 842, kReportPageHeightPt = 595;

// Writes into `dir` (created if missing):
//   recall_by_side.png   P_Rec against the marker's side in pixels (cells of equal side pooled over light), a
//                        line per detector with 95 % Wilson error bars;
//   recall_by_light.png  P_Rec against lux (pooled over sizes and distances), a line per detector;
//   recall_by_tilt.png   P_Rec against the marker's tilt, frame by frame in 10-degree bins, a line per detector;
//   recall_by_blur.png   P_Rec against the cell's whole blur in px (CellResult::blur_px), cells in bins;
//   heatmap_<detector>.png  size (rows) x distance (columns), colour and number = P_Rec pooled over light;
//   heatmap_<detector>_<lux>lx.png  the same under each light, when the plan has more than one;
//   report.pdf           a title page (plan, camera, sensor, seed, time), the paper's table (a page per detector:
//                        a row per size and distance, a column per light), then the plots above, one per page.
// Each file is drawn under a temporary name (".arwb-saving") and renamed when complete. An error names the folder or file that
// could not be written, or the PLplot device that is missing; results without cells or detectors are an error.
Status write_lab_report(const LabResults& r, const std::string& dir);

// Everything a run leaves: table.txt, table.csv and results.json (run.hpp), then write_lab_report's plots and
// report.pdf, into `dir` (made when missing). The first file that cannot be written is the error.
Status write_lab_outputs(const LabResults& r, const std::string& dir);

// The PNG files write_lab_report writes for `r`, in the order they appear in report.pdf.
std::vector<std::string> lab_report_png_names(const LabResults& r);

}  // namespace arwb::lab
