// Joining the wave band to the ray-traced IR: the ray-traced channel high-passed and the wave
// band low-passed at the crossover by a power-complementary pair (4th-order Butterworth,
// common/butterworth.h: |H_lp|^2 + |H_hp|^2 = 1), so the joined IR's energy per frequency is
// the wave band's below the crossover, the ray band's above and their power mean at it (-3 dB
// each); both filters are causal, so nothing moves before the direct sound.
//
// How the omnidirectional wave band enters each output channel (`waveBandGain`): mono, and
// each ear of binaural output, take it whole (below a few hundred hertz the head barely shades
// one ear); stereo and loudspeaker outputs share its power equally (1 / sqrt(channels)); AmbiX
// puts it in W (ACN 0, SN3D: the pressure) and nowhere else.
//
// Control thread; joinWaveBand allocates a copy of the wave band; no errors (requires
// 0 < crossoverHz < fs / 2, checked by the scene's validation).
#pragma once

#include <span>

#include "scene/scene.h"

namespace dpc::wave {

/// Order of each crossover filter.
inline constexpr int kCrossoverOrder = 4;

/// The wave band's gain in output channel `channel` of `format` with `channels` channels.
double waveBandGain(OutputFormat format, int channel, int channels);

/// rayChannel <- HP(rayChannel) + gain * LP(wave), over rayChannel's length (fs: both signals'
/// rate, Hz).
void joinWaveBand(std::span<float> rayChannel, std::span<const float> wave, double gain,
                  double crossoverHz, double fs);

}  // namespace dpc::wave
