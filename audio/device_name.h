// Device naming: what an output device is called (DeviceInfo, its "HOSTAPI:NAME" spec) and
// which backend a device spec (`--device SPEC` in the apps) selects.
//
// Device specs:
//   ""  or "default"   JACK (physical playback ports) if a JACK server is running, otherwise
//                      PortAudio's default output device, otherwise the first output device.
//   "jack:" / "jack:system"  JACK, connected to the physical playback ports.
//   "jack:CLIENT"      JACK, connected in order to the input ports of client CLIENT (e.g. an
//                      Ambisonic decoder's); an error if no such client has input ports.
//   "NAME"             the first PortAudio output device whose name contains NAME
//                      (case-insensitive); an exact (case-insensitive) match wins.
//   "HOSTAPI:NAME"     as "NAME" but only among devices of the host API whose name contains
//                      HOSTAPI (case-insensitive): "alsa:hw:0,0", "ALSA:pulse".
//                      "HOSTAPI:" alone is that host API's default output.
//   "portaudio:SPEC"   SPEC through PortAudio even for JACK ("portaudio:jack:system").
//   If HOSTAPI matches no host API, or NAME matches nothing there, the whole SPEC is tried as
//   a NAME (device names may contain ':', e.g. "HDA Intel PCH: ALC892 Analog (hw:0,0)").
// PortAudio resolves its part of a spec (audio/portaudio_backend.h), the JACK backend its
// client name (audio/jack_backend.h).
//
// Threads: any thread (plain functions of strings). Allocation: the returned strings. No errors.
#pragma once

#include <string>

namespace dpc::audio {

/// One output device, as listOutputDevices() (audio/portaudio_backend.h) lists it or as an
/// AudioOutput opened it.
struct DeviceInfo {
  std::string name;                      ///< PortAudio device name, e.g. "system" (JACK)
  std::string hostApi;                   ///< host API name, e.g. "JACK Audio Connection Kit"
  int maxOutputChannels = 0;             ///< > 0 for every listed device
  double defaultSampleRate = 0.0;        ///< Hz
  double defaultLowOutputLatency = 0.0;  ///< seconds (PortAudio's estimate for interactive use)
  bool isDefault = false;  ///< the device an empty --device spec opens (see the file comment)
  /// "HOSTAPI:NAME" with the host API's short name ("JACK", "ALSA", "OSS"): a spec that
  /// selects exactly this device's host API.
  std::string spec() const;
};

/// `s` with ASCII letters in lower case (device names and specs compare case-insensitively).
std::string lowerCase(std::string s);
/// Whether `haystack` contains `needle`, ignoring ASCII case ("" is in everything).
bool containsNoCase(const std::string& haystack, const std::string& needle);

/// The backend a device spec selects and what it names there.
struct DeviceRoute {
  enum class Backend { kPortAudio, kJack };
  Backend backend = Backend::kPortAudio;
  /// PortAudio: the spec to resolve (without "portaudio:"); JACK: the client to connect to
  /// ("" : the physical playback ports).
  std::string name;
};

/// The route of `spec` (see the file comment): "portaudio:SPEC" to PortAudio, "jack:CLIENT"
/// (any case; "jack:system" and "jack:" are the physical ports) to JACK, the default ("" or
/// "default") to JACK when jackServerRunning() says a server runs, everything else to
/// PortAudio. jackServerRunning is called only for the default spec.
DeviceRoute routeDeviceSpec(const std::string& spec, bool (*jackServerRunning)());

}  // namespace dpc::audio
