// The output format's shape: how many channels an output's IRs have and how many the audio
// stage renders, what the rendered channels are called, over which directions the spatial
// synthesis shares the diffuse energy, and the spatial IR synthesiser for the format
// (constant-power panning, HRIRs, Ambisonic encoding or VBAP over a loudspeaker layout).
// The propagation stage, the hybrid synthesis, the renderers and the apps take these from here.
//
// Threads: any thread, except makeSpatialSynthesizer (control thread). Allocation and errors:
// per function below.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "synthesis/spatial_synthesizer.h"

namespace dpc {

/// IR channels of an output: 1 for mono, 2 for stereo and binaural, (order + 1)^2 for
/// Ambisonics and head-tracked binaural, one per loudspeaker. Any thread; no allocation.
int irChannels(const AudioSettings& audio);
/// Channels the audio stage renders (files, devices): irChannels(), except 2 (ears) for
/// head-tracked binaural, whose (order + 1)^2 IR channels are decoded per block. Any thread;
/// no allocation.
int renderedChannels(const AudioSettings& audio);
/// A name per rendered channel, as live outputs label their ports: "mono"; "left", "right"
/// (stereo, binaural, head-tracked binaural); "ACN0" ... (Ambisonics, ACN order); the
/// loudspeakers' labels (layouts). Any thread; allocates.
std::vector<std::string> renderedChannelNames(const AudioSettings& audio);

/// Independent directions per Ambisonic channel the diffuse energy of a turned field is
/// synthesised over: with K = 2 (N + 1)^2 spherical-Fibonacci directions the eigenvalues of
/// their Gram matrix of orthonormal (N3D) harmonics, sum_k y(u_k) y(u_k)^T 4 pi / K, lie
/// within 0.80-1.13 at every order 1-7 (a diffuse field's: 1), so the late field's
/// (N + 1)^2 channels have a full-rank, nearly white covariance; with K = (N + 1)^2 the
/// smallest falls to 0.03-0.6, and a count below (N + 1)^2 leaves the covariance rank K.
/// Cost per direction: 8 x IR length floats of memory (3 MB for a 2 s IR at 48 kHz) and
/// one more enveloped signal per frame (docs/spatial.md, "Diffuseness of the Ambisonic late
/// field").
inline constexpr int kTurnedFieldDirectionsPerChannel = 2;
/// The listener-frame directions the spatial synthesiser shares the diffuse energy among:
/// defaultSpatialDirections() for stereo, binaural and loudspeakers; for a field turned after
/// synthesis (Ambisonics, head-tracked binaural) uniformSpatialDirections() of
/// kTurnedFieldDirectionsPerChannel (N + 1)^2, so no direction relative to the head is
/// favoured: the audio-rate turn then matches a re-synthesis at the new orientation per octave
/// band within about half a dB (8 horizon-heavy directions: 2.2 dB, 16 uniform: 1 dB;
/// tests/runtime/head_tracking_test.cpp). Unit vectors. Any thread; allocates.
std::vector<glm::vec3> spatialDirections(const AudioSettings& audio);

/// The spatial IR synthesiser for scene.audio.output (stereo: constant-power panning;
/// binaural: HRIRs from scene.audio.hrtfPath at the scene's rate; Ambisonics: ACN/SN3D gains,
/// max-rE weighted when asked; loudspeakers: VBAP with the layout's distance compensation)
/// over spatialDirections(scene.audio), for IRs of settings.irLength seconds in a room of
/// roomVolume m^3. Control thread; allocates; throws InputError naming audio.hrtf for an
/// unreadable SOFA file, or the layout's "speakers" for a layout VBAP cannot pan over.
std::unique_ptr<SpatialIrSynthesizer> makeSpatialSynthesizer(const SceneDesc& scene,
                                                             const PropagationSettings& settings,
                                                             double roomVolume);
/// The same for IRs of lengthSeconds, with the Dirac sequences' seed salted by seedSalt (a
/// second synthesiser whose noise is independent of the first's; 0: unsalted).
std::unique_ptr<SpatialIrSynthesizer> makeSpatialSynthesizer(const SceneDesc& scene,
                                                             const PropagationSettings& settings,
                                                             double roomVolume,
                                                             double lengthSeconds,
                                                             uint64_t seedSalt);

}  // namespace dpc
