#include "audio/jack_backend.h"

#include <jack/jack.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "audio/output_backend.h"

namespace dpc::audio {

namespace {

constexpr const char* kJackApi = "JACK Audio Connection Kit";

/// Frees a jack_get_ports() list.
struct PortList {
  const char** names = nullptr;
  ~PortList() {
    if (names) jack_free(const_cast<char**>(names));
  }
  size_t size() const {
    size_t n = 0;
    while (names && names[n]) ++n;
    return n;
  }
};

/// Opens a client without starting a server; nullptr if none runs. JACK's "server is not
/// running" diagnostics are silenced.
jack_client_t* openClient(const std::string& name) {
  quietAudioProbing(true);
  jack_status_t status{};
  jack_client_t* c = jack_client_open(name.c_str(), JackNoStartServer, &status);
  quietAudioProbing(false);
  return c;
}

class JackBackend final : public OutputBackend {
 public:
  JackBackend(const OutputOptions& options, const std::string& target);
  ~JackBackend() override { close(); }
  void start() override;
  void stop() override {
    if (active_.exchange(false)) jack_deactivate(client_);
  }
  void close() override {
    if (!client_) return;
    if (active_.exchange(false)) jack_deactivate(client_);
    jack_client_close(client_);
    client_ = nullptr;
  }
  bool isActive() const override { return active_.load() && !serverGone_.load(); }
  bool stopWithin(double seconds) override {
    if (!active_.exchange(false)) return true;
    jack_client_t* c = client_;
    return runWithin([c] { jack_deactivate(c); }, seconds);
  }

 private:
  void registerPorts(const OutputOptions& options);
  void findTargets(const std::string& target, bool connectPhysical);
  double targetLatencySeconds() const;

  // JACK's process thread: the ports' buffers, then the shared render(). jack_port_get_buffer
  // is real-time safe; no allocation, locks or system calls.
  static int process(jack_nframes_t frames, void* arg) noexcept {
    auto* self = static_cast<JackBackend*>(arg);
    std::array<float*, kMaxJackChannels> out{};
    for (int c = 0; c < self->channels; ++c)
      out[size_t(c)] = static_cast<float*>(jack_port_get_buffer(self->ports_[size_t(c)], frames));
    self->render(out.data(), int(frames), self->xruns_.exchange(0, std::memory_order_relaxed) > 0);
    return 0;
  }
  // JACK's notification thread: counted, then flagged on the next callback.
  static int xrun(void* arg) noexcept {
    static_cast<JackBackend*>(arg)->xruns_.fetch_add(1, std::memory_order_relaxed);
    return 0;
  }
  static int bufferSize(jack_nframes_t frames, void* arg) noexcept {
    static_cast<JackBackend*>(arg)->blockSize.store(int(frames), std::memory_order_relaxed);
    return 0;
  }
  // The server shut down or was killed: the stream is no longer active (the watchdog ends
  // the session).
  static void shutdown(jack_status_t, const char*, void* arg) noexcept {
    static_cast<JackBackend*>(arg)->serverGone_.store(true);
  }

  jack_client_t* client_ = nullptr;
  std::vector<jack_port_t*> ports_;
  std::vector<std::string> targets_;  ///< input ports to connect to, in channel order
  std::atomic<bool> active_{false};
  std::atomic<bool> serverGone_{false};
  std::atomic<int> xruns_{0};
};

JackBackend::JackBackend(const OutputOptions& options, const std::string& target) {
  device.name = target.empty() ? "system" : target;
  device.hostApi = kJackApi;
  client_ = openClient(options.clientName.empty() ? "dpc" : options.clientName);
  if (!client_)
    throw std::runtime_error(where() +
                             ": no JACK server is running (start one, e.g. jackd -d dummy "
                             "-r 48000 -p 128)");
  sampleRate = double(jack_get_sample_rate(client_));
  blockSize = int(jack_get_buffer_size(client_));
  realTimeCallback = jack_is_realtime(client_) != 0;
  channels = options.channels;
  device.defaultSampleRate = sampleRate;
  try {
    if (options.sampleRate != sampleRate)
      throw std::runtime_error(where() + ": " + std::to_string(int(options.sampleRate)) +
                               " Hz not supported (the JACK server runs at " +
                               std::to_string(int(sampleRate)) +
                               " Hz; a JACK device runs only at the server's rate)");
    if (channels > kMaxJackChannels)
      throw std::runtime_error(where() + ": " + std::to_string(channels) +
                               " output channels requested, at most " +
                               std::to_string(kMaxJackChannels));
    findTargets(target, options.connectPhysical);
    registerPorts(options);
  } catch (...) {
    jack_client_close(client_);
    throw;
  }
  device.defaultLowOutputLatency = outputLatency = targetLatencySeconds();
}

void JackBackend::findTargets(const std::string& target, bool connectPhysical) {
  PortList list;
  if (target.empty()) {
    list.names = jack_get_ports(client_, nullptr, JACK_DEFAULT_AUDIO_TYPE,
                                JackPortIsPhysical | JackPortIsInput);
  } else {
    // Ports of exactly that client: its name, then ':' (the pattern is a regular expression).
    std::string pattern = "^";
    for (char ch : target) {
      if (std::strchr(".[]()*+?^$|\\{}", ch)) pattern += '\\';
      pattern += ch;
    }
    list.names =
        jack_get_ports(client_, (pattern + ":").c_str(), JACK_DEFAULT_AUDIO_TYPE, JackPortIsInput);
    if (list.size() == 0)
      throw std::runtime_error(where() + ": no JACK client '" + target +
                               "' with audio input ports (jack_lsp lists them)");
  }
  device.maxOutputChannels = int(list.size());
  if (target.empty() && !connectPhysical) return;
  for (size_t i = 0; i < list.size() && int(i) < channels; ++i)
    targets_.emplace_back(list.names[i]);
}

void JackBackend::registerPorts(const OutputOptions& options) {
  for (int c = 0; c < channels; ++c) {
    const std::string name = size_t(c) < options.channelNames.size()
                                 ? options.channelNames[size_t(c)]
                                 : "out_" + std::to_string(c + 1);
    jack_port_t* p = jack_port_register(client_, name.c_str(), JACK_DEFAULT_AUDIO_TYPE,
                                        JackPortIsOutput | JackPortIsTerminal, 0);
    if (!p) throw std::runtime_error(where() + ": cannot register the JACK port '" + name + "'");
    ports_.push_back(p);
  }
  jack_set_process_callback(client_, &JackBackend::process, this);
  jack_set_xrun_callback(client_, &JackBackend::xrun, this);
  jack_set_buffer_size_callback(client_, &JackBackend::bufferSize, this);
  jack_on_info_shutdown(client_, &JackBackend::shutdown, this);
}

/// The playback latency of the first port connected to, seconds (the driver's buffering);
/// one period when nothing is connected.
double JackBackend::targetLatencySeconds() const {
  jack_latency_range_t range{0, 0};
  if (!targets_.empty())
    if (jack_port_t* p = jack_port_by_name(client_, targets_[0].c_str()))
      jack_port_get_latency_range(p, JackPlaybackLatency, &range);
  const double frames = range.max > 0 ? double(range.max) : double(blockSize.load());
  return frames / sampleRate;
}

void JackBackend::start() {
  if (active_.load()) return;
  if (!client_) throw std::runtime_error(where() + ": the JACK client was closed");
  if (serverGone_.load()) throw std::runtime_error(where() + ": the JACK server has shut down");
  if (jack_activate(client_) != 0)
    throw std::runtime_error(where() + ": cannot activate the JACK client");
  active_ = true;
  for (size_t c = 0; c < targets_.size(); ++c) {
    const int err = jack_connect(client_, jack_port_name(ports_[c]), targets_[c].c_str());
    if (err != 0 && err != EEXIST)
      throw std::runtime_error(where() + ": cannot connect " + jack_port_name(ports_[c]) + " to " +
                               targets_[c]);
  }
}

}  // namespace

bool jackServerRunning() {
  jack_client_t* c = openClient("dpc-probe");
  if (!c) return false;
  jack_client_close(c);
  return true;
}

std::unique_ptr<OutputBackend> openJackOutput(const OutputOptions& options,
                                              const std::string& target) {
  return std::make_unique<JackBackend>(options, target);
}

}  // namespace dpc::audio
