// Fuzz target: the URL check (src/media/media_path.cpp: check_url, url_host) that every web link of a scene or a
// database passes before a card shows it or xdg-open is started on it. What it accepts must be what it promises:
// http or https, a host, no space or control character, at most 2048 characters; the host is part of the URL, and
// it is the host a browser opens (the WHATWG URL standard's reading of the authority, written here independently
// for the URLs check_url accepts), since a web card shows that host as its title.
#include "media/media_path.hpp"

#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

namespace {

// The host a browser opens for an http(s) URL that check_url accepted: for these "special" schemes the authority
// ends at '/', '\\', '?' or '#'; userinfo ends at its last '@'; a port follows the last ':' outside brackets.
std::string browser_host(std::string_view url) {
  std::string_view rest = url.substr(url.find(':') + 3);
  rest = rest.substr(0, rest.find_first_of("/\\?#"));
  if (const size_t at = rest.rfind('@'); at != std::string_view::npos) rest = rest.substr(at + 1);
  if (rest.starts_with('[')) return std::string(rest.substr(0, rest.find(']') + 1));
  return std::string(rest.substr(0, rest.find(':')));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string url(reinterpret_cast<const char*>(data), size);
  const std::string why = arwb::media::check_url(url);
  const std::string host = arwb::media::url_host(url);
  if (!host.empty() && url.find(host) == std::string::npos) std::abort();
  if (!why.empty()) return 0;
  if (url.size() > 2048 || host.empty()) std::abort();
  std::string scheme;
  for (char c : url.substr(0, url.find(':'))) scheme += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (scheme != "http" && scheme != "https") std::abort();
  for (unsigned char c : url)
    if (c <= 0x20 || c == 0x7F) std::abort();
  if (host != browser_host(url)) std::abort();   // the card would name another host than the one opened
  return 0;
}
