// [SECTION] Index
//   Serve section  File > Export...'s Serve: the bundle just written (with its phone page) on 127.0.0.1, its address
//                  as text and as a QR code, the way to a phone, the requests answered
//   Requests       starting the server off the UI thread; stopping it
//   Polling        a server started, or refused
// `arwb serve` in the window (serve/bundle_server.hpp does the work). The section only draws the dialog's state.
#include "ui/app.hpp"

#include "serve/qr_code.hpp"

#include <imgui.h>

#include <chrono>
#include <utility>

namespace arwb {

// [SECTION] Serve section
void App::draw_serve_section(ui::Context& ctx, float width) {
  ExportDialog& d = export_dialog;
  if (!d.server && (d.written.empty() || !d.written_web)) return;
  ImGui::Separator();
  if (!d.server) {
    ImGui::BeginDisabled(d.serve_starting.valid());
    if (ImGui::Button("Serve to a phone")) requests.push_back(ui::ServeBundle{true});
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::TextDisabled(d.serve_starting.valid() ? "verifying the bundle..."
                                                  : "on this computer's 127.0.0.1, as `arwb serve` does");
    if (!d.serve_error.empty()) ImGui::TextColored({1, 0.35f, 0.3f, 1}, "%s", d.serve_error.c_str());
    return;
  }
  const serve::BundleServer& s = *d.server;
  const float side = float(d.server_qr.cols) * ctx.scale;
  ImGui::Image(ctx.texture("serve_qr", d.server_qr, std::uint64_t(s.port())), {side, side});
  ImGui::SameLine();
  ImGui::BeginGroup();
  ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + std::max(width - side, 200.0f));
  ImGui::TextUnformatted("Serving at");
  std::string url = s.url();
  ImGui::SetNextItemWidth(std::max(width - side, 200.0f) * 0.7f);
  ImGui::InputText("##serve_url", url.data(), url.size() + 1, ImGuiInputTextFlags_ReadOnly);
  ImGui::TextUnformatted(serve::phone_advice(s.port()).c_str());
  const std::string last = s.last_request();
  ImGui::TextDisabled("%llu requests answered%s%s", static_cast<unsigned long long>(s.requests()),
                      last.empty() ? "" : "; the last: ", last.c_str());
  if (ImGui::Button("Stop serving")) requests.push_back(ui::ServeBundle{false});
  ImGui::PopTextWrapPos();
  ImGui::EndGroup();
}

// [SECTION] Requests
void App::serve_bundle(bool on) {
  ExportDialog& d = export_dialog;
  if (!on) {
    if (!d.server) return;
    const std::string url = d.server->url();
    const auto n = d.server->requests();
    d.server.reset();
    info("serve: stopped serving " + url + " after " + std::to_string(n) + " requests");
    return;
  }
  if (d.server || d.serve_starting.valid()) return warn("serve: the bundle is being served already");
  if (d.written.empty() || !d.written_web) {
    d.serve_error = "export the bundle with 'add a web page for phones' first";
    return error("serve: " + d.serve_error);
  }
  d.serve_error.clear();
  // Port 8000, what `arwb serve` takes, so that one `adb reverse tcp:8000 tcp:8000` serves both; any free one when
  // another program has it. Verifying a bundle reads every byte: off the UI thread.
  serve::ServeOptions o;
  o.any_port_if_taken = true;
  d.serve_starting = std::async(std::launch::async, [path = d.written, o] { return serve::BundleServer::start(path, o); });
  info("serve: verifying " + d.written);
}

// [SECTION] Polling
void App::poll_serve() {
  ExportDialog& d = export_dialog;
  if (!d.serve_starting.valid() || d.serve_starting.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
    return;
  Result<serve::BundleServer> started = d.serve_starting.get();
  if (std::exchange(d.serve_stale, false)) {
    info("serve: the bundle was written again while its server started: press Serve to a phone again");
    return;   // the server goes with `started`
  }
  if (!started) {
    d.serve_error = started.error();
    return error("serve: " + d.serve_error);
  }
  d.server.emplace(std::move(*started));
  // The QR code as a picture: 4 pixels a module and the standard's quiet zone of 4 modules, black on white.
  d.server_qr.release();
  if (const Result<serve::QrCode> qr = serve::make_qr(d.server->url())) {
    constexpr int kPx = 4, kQuiet = 4;
    d.server_qr.create((qr->size + 2 * kQuiet) * kPx, (qr->size + 2 * kQuiet) * kPx, CV_8UC1);
    for (int y = 0; y < d.server_qr.rows; ++y)
      for (int x = 0; x < d.server_qr.cols; ++x)
        d.server_qr.at<std::uint8_t>(y, x) = qr->at(x / kPx - kQuiet, y / kPx - kQuiet) ? 0 : 255;
  }
  note_status("serve: " + d.written + " at " + d.server->url());
}

}  // namespace arwb
