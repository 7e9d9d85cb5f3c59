// Opening a web link in the system's default browser: checked with check_url, then started with posix_spawnp
// and an argument vector ({"xdg-open", url}), never through a shell, so no character of the URL is interpreted.
// ARWB_URL_OPENER names another program to start instead (tests use it to record what would be opened).
#pragma once

#include <string>

namespace arwb::media {

// Empty on success (the opener was started; it is not waited for, but reaped by a detached thread when it
// ends, so it leaves no zombie), else the reason: check_url's ("ftp://x: only http and https links are
// opened") or "cannot start xdg-open: No such file or directory". ARWB_URL_OPENER is one program (looked up in
// PATH like xdg-open), not a command line.
std::string open_url(const std::string& url);

}  // namespace arwb::media
