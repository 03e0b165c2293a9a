// The PortAudio backend of AudioOutput (http://www.portaudio.com, v19): ALSA, OSS, and JACK
// through PortAudio, with a fixed block size. Resolves the PortAudio part of a device spec
// (audio/device_name.h) to one of PortAudio's output devices and lists them.
//
// PortAudio's initialisation is reference-counted per object: each open stream (and each
// listOutputDevices() call) holds one reference and releases only its own, under one mutex
// (Pa_Initialize and Pa_Terminate are not thread-safe). While PortAudio initialises or
// terminates, ALSA's and JACK's diagnostics are silenced (quietAudioProbing,
// audio/output_backend.h).
//
// Threads: control thread; the stream's callback runs on PortAudio's audio thread
// (OutputBackend::render). Allocation: both functions allocate. Errors: std::runtime_error with
// a one-line message naming the device (see each function).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "audio/device_name.h"
#include "audio/output_options.h"

namespace dpc::audio {

class OutputBackend;  // audio/output_backend.h

/// All PortAudio devices with at least one output channel, in PortAudio's order (grouped by
/// host API). Control thread. Allocates; initialises PortAudio for the duration of the call
/// (host APIs probe their devices: takes up to ~100 ms, and ALSA/JACK may print diagnostics on
/// stderr). Returns an empty vector if there are none. Throws std::runtime_error if PortAudio
/// cannot be initialised.
std::vector<DeviceInfo> listOutputDevices();

/// Opens (does not start) a PortAudio stream of options.channels float32 planar channels at
/// options.sampleRate with options.blockSize frames per callback on the device `spec` names
/// (audio/device_name.h, without "portaudio:"). On ALSA it asks for SCHED_FIFO for the callback
/// thread. Throws std::runtime_error naming the device: PortAudio initialisation failed, no
/// output device at all, no device matches (the message lists the available ones), too many
/// channels, a rate or channel count the device does not support, the stream cannot be opened.
std::unique_ptr<OutputBackend> openPortAudioOutput(const OutputOptions& options,
                                                   const std::string& spec);

}  // namespace dpc::audio
