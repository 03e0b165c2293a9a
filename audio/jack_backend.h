// The JACK backend of AudioOutput: a client of JACK's own library (https://jackaudio.org/api/)
// with one named output port per channel, called at the server's period, connected on start to
// the physical playback ports or to another client's inputs, and told when the server shuts
// down (the stream then is no longer active).
//
// Threads: control thread; the client's process callback runs on JACK's process thread
// (OutputBackend::render), its xrun and buffer-size notices on JACK's notification thread
// (relaxed atomics). Allocation: both functions allocate. Errors: std::runtime_error naming
// the device (see openJackOutput).
#pragma once

#include <memory>
#include <string>

#include "audio/output_options.h"

namespace dpc::audio {

class OutputBackend;  // audio/output_backend.h

/// Whether a JACK server is running (a client opened without starting one; JACK's "server is
/// not running" diagnostics silenced). Control thread; takes a few ms; no errors.
bool jackServerRunning();

/// Opens a JACK client with options.channels output ports (named options.channelNames, else
/// "out_1"...) connected, once started, to the input ports of client `target` in order
/// ("" : the physical playback ports, unless options.connectPhysical is false). The stream runs
/// at the server's rate and period. Throws std::runtime_error naming the device: no server, a
/// sample rate other than the server's, more than kMaxJackChannels channels, no
/// such target client, a port that cannot be registered.
std::unique_ptr<OutputBackend> openJackOutput(const OutputOptions& options,
                                              const std::string& target);

}  // namespace dpc::audio
