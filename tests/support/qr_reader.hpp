// QR codes read back with ZBar (Debian: libzbar-dev), a decoder that shares nothing with libqrencode, which arwb
// writes them with. Header-only: only the test binaries that read QR codes link ZBar.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <zbar.h>

#include <string>

namespace arwb::test {

// The text of the first QR code in `image` (grey or BGR), "" when none reads.
inline std::string read_qr(const cv::Mat& image) {
  using namespace zbar;   // zbar.h puts its C API in namespace zbar when compiled as C++
  cv::Mat grey;
  if (image.channels() == 1) grey = image.clone();
  else cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  zbar_image_scanner_t* scanner = zbar_image_scanner_create();
  zbar_image_scanner_set_config(scanner, ZBAR_NONE, ZBAR_CFG_ENABLE, 0);
  zbar_image_scanner_set_config(scanner, ZBAR_QRCODE, ZBAR_CFG_ENABLE, 1);
  zbar_image_t* z = zbar_image_create();
  zbar_image_set_format(z, zbar_fourcc('Y', '8', '0', '0'));
  zbar_image_set_size(z, unsigned(grey.cols), unsigned(grey.rows));
  zbar_image_set_data(z, grey.data, grey.total(), nullptr);
  std::string text;
  if (zbar_scan_image(scanner, z) > 0) text = zbar_symbol_get_data(zbar_image_first_symbol(z));
  zbar_image_destroy(z);
  zbar_image_scanner_destroy(scanner);
  return text;
}

}  // namespace arwb::test
