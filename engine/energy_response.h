// EnergyResponse: band energy arriving at the listener per time bin.
//
// bins[k][b] = intensity in octave band b that arrives with a delay in [k*binSeconds,
// (k+1)*binSeconds), relative to the source's emitted power, in 1/m^2 (the direct sound at
// distance r contributes 1/(4 pi r^2), before air absorption). It is what the estimators
// (path tracing, the diffuse path cache) produce each frame and what IR synthesis turns
// into pressure.
// Propagation thread. The constructor allocates; add/clear do not. No errors: arrivals at or
// beyond the length are counted in droppedEnergy() (nothing is lost silently).
#pragma once

#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"

namespace dpc {

class EnergyResponse {
 public:
  EnergyResponse() = default;
  /// lengthSeconds > 0, binSeconds > 0.
  EnergyResponse(double lengthSeconds, double binSeconds);

  /// Adds band intensity at a delay in seconds (>= 0).
  void add(double delaySeconds, const Bands& intensity) {
    const double k = delaySeconds * invBin_;
    if (k >= 0.0 && k < double(bins_.size()))
      bins_[size_t(k)] += intensity;
    else
      dropped_ += intensity;
  }
  void clear();

  double binSeconds() const { return binSeconds_; }
  size_t binCount() const { return bins_.size(); }
  const std::vector<Bands>& bins() const { return bins_; }
  std::vector<Bands>& bins() { return bins_; }
  /// Intensity that arrived too late to be stored since the last clear().
  const Bands& droppedEnergy() const { return dropped_; }
  /// Sum over all bins per band.
  Bands total() const;
  /// The same response in coarser bins of factor * binSeconds (allocates).
  EnergyResponse rebinned(size_t factor) const;

 private:
  double binSeconds_ = 1e-3, invBin_ = 1e3;
  std::vector<Bands> bins_;
  Bands dropped_{0.f};
};

/// Receives a response's arrivals one at a time: band intensity (1/m^2) at a delay (s) from a
/// world direction (unit vector from the listener toward where the sound comes from). The
/// estimators (engine/path_cache.h) and the exact paths (engine/specular_paths.h) hand every
/// arrival to one, whatever it keeps: the panned responses below, or spherical-harmonic
/// energy (engine/sh_energy_response.h).
class ArrivalSink {
 public:
  virtual ~ArrivalSink() = default;
  virtual void add(double delaySeconds, const Bands& intensity,
                   const glm::vec3& worldDirection) = 0;
};

/// Hands every arrival to two sinks (both must outlive it). No allocation.
class ArrivalTee final : public ArrivalSink {
 public:
  ArrivalTee(ArrivalSink* first = nullptr, ArrivalSink* second = nullptr)
      : first_(first), second_(second) {}
  void add(double delaySeconds, const Bands& intensity, const glm::vec3& direction) override {
    first_->add(delaySeconds, intensity, direction);
    second_->add(delaySeconds, intensity, direction);
  }

 private:
  ArrivalSink* first_;
  ArrivalSink* second_;
};

/// A listener's frame: x forward, y left, z up (the SOFA and AmbiX convention), from its world
/// forward and up vectors (unit, orthogonal after setting). The default is a listener at yaw 0,
/// pitch 0: forward +x, up +y, so left is -z (world y up, right-handed).
struct ListenerFrame {
  glm::vec3 forward{1.f, 0.f, 0.f}, left{0.f, 0.f, -1.f}, up{0.f, 1.f, 0.f};
  /// The frame of a listener facing `forward` with `up` (not parallel to it).
  void set(const glm::vec3& forward, const glm::vec3& up);
  /// World direction -> listener frame (x forward, y left, z up).
  glm::vec3 toListener(const glm::vec3& world) const;
  /// Listener frame -> world direction.
  glm::vec3 toWorld(const glm::vec3& listener) const {
    return forward * listener.x + left * listener.y + up * listener.z;
  }
};

/// Energy response split over K fixed directions in the listener's frame (x forward, y left,
/// z up: the SOFA convention), for spatial IR synthesis. An arrival from world direction d
/// (unit vector from the listener toward where the sound comes from) is rotated into the
/// listener frame and shared among the K directions v_k with energy weights
/// w_k = max(0, d.v_k)^p / sum_j max(0, d.v_j)^p (a cosine-power panning in energy: the weights
/// sum to 1, so the K responses add up to the plain energy response).
/// Propagation thread. Construction and setDirections allocate; add/clear do not.
class DirectionalEnergyResponse final : public ArrivalSink {
 public:
  DirectionalEnergyResponse() = default;
  /// directions: K >= 1 unit vectors in the listener frame; exponent p > 0.
  DirectionalEnergyResponse(double lengthSeconds, double binSeconds,
                            std::vector<glm::vec3> directions, float exponent = 4.f);

  /// The listener's orientation in world coordinates (unit, orthogonal): forward and up.
  void setListenerFrame(const glm::vec3& forward, const glm::vec3& up) { frame_.set(forward, up); }
  /// World direction -> listener frame (x forward, y left, z up).
  glm::vec3 toListener(const glm::vec3& world) const { return frame_.toListener(world); }
  /// Listener frame -> world direction.
  glm::vec3 toWorld(const glm::vec3& listener) const { return frame_.toWorld(listener); }

  void add(double delaySeconds, const Bands& intensity, const glm::vec3& worldDirection) override;
  void clear();

  size_t directionCount() const { return responses_.size(); }
  const glm::vec3& direction(size_t k) const { return directions_[k]; }
  const EnergyResponse& response(size_t k) const { return responses_[k]; }
  /// The same directions, frame and bin width over the first lengthSeconds, empty (allocates).
  DirectionalEnergyResponse truncated(double lengthSeconds) const;
  /// Takes other's listener frame (its directions must be these). No allocation.
  void copyFrame(const DirectionalEnergyResponse& other) { frame_ = other.frame_; }
  /// The listener frame its directions are in.
  const ListenerFrame& frame() const { return frame_; }
  /// Direction k's response to edit in place (e.g. hybrid rendering's early/late split).
  EnergyResponse& response(size_t k) { return responses_[k]; }

 private:
  std::vector<glm::vec3> directions_;
  std::vector<EnergyResponse> responses_;
  float exponent_ = 4.f;
  ListenerFrame frame_;
  std::vector<float> weights_;  ///< scratch, K
};

}  // namespace dpc
