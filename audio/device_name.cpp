#include "audio/device_name.h"

#include <cctype>

namespace dpc::audio {

std::string lowerCase(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool containsNoCase(const std::string& haystack, const std::string& needle) {
  return lowerCase(haystack).find(lowerCase(needle)) != std::string::npos;
}

std::string DeviceInfo::spec() const {
  std::string api = hostApi;
  if (containsNoCase(hostApi, "jack")) api = "JACK";
  return api + ":" + name;
}

DeviceRoute routeDeviceSpec(const std::string& spec, bool (*jackServerRunning)()) {
  using Backend = DeviceRoute::Backend;
  const std::string l = lowerCase(spec);
  if (l.rfind("portaudio:", 0) == 0) return {Backend::kPortAudio, spec.substr(10)};
  if (l.rfind("jack:", 0) == 0) {
    std::string target = spec.substr(5);
    if (lowerCase(target) == "system") target.clear();
    return {Backend::kJack, target};
  }
  if ((l.empty() || l == "default") && jackServerRunning()) return {Backend::kJack, ""};
  return {Backend::kPortAudio, spec};
}

}  // namespace dpc::audio
