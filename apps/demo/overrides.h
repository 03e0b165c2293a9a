// Command-line overrides of a scene's settings, and the checks of dpc-demo's output paths.
#pragma once

#include "apps/demo/flags.h"
#include "scene/scene.h"

namespace dpc::demo {

/// The scene's propagation settings with --seed, --rays, --max-order, --tau,
/// --cache-memory-mb, --threads, --estimator, --tracing and --dpc-weighting applied. Main thread.
/// Throws InputError ("command line", flag, why) for a value out of range or unknown.
PropagationSettings applyOverrides(const SceneDesc& scene, const Flags& fl);

/// --output / --hrtf: the scene's audio output settings, overridden in place; --listener's
/// name is checked. Main thread. Throws InputError for an unknown format or listener, or a
/// SOFA file that does not exist.
void applyAudioOverrides(SceneDesc& scene, const Flags& fl);

/// --rendering, --late-buses, --cluster-angle (hybrid rendering) and --block-size into
/// `audio`; called by applyAudioOverrides. Main thread. Throws InputError naming the flag.
void applyRenderingOverrides(AudioSettings& audio, const Flags& fl);

/// Throws InputError("command line", FLAG, ...) for a flag the settings make useless (--hrtf
/// with an output that uses no HRTF, --ambisonic-order without Ambisonic output, --max-re but
/// with ambisonics output (the binaural decoders weigh their own),
/// --binaural-decoder without ambisonic_binaural, --late-buses or --cluster-angle with
/// per-source rendering): accepted, it would change nothing without a word. Main thread.
void refuseUnusedAudioFlags(const AudioSettings& audio, const Flags& fl);

/// --listener: the listener played or rendered (scene.listeners index); the first without it.
/// Main thread. Throws InputError for an unknown name.
size_t selectedListener(const SceneDesc& scene, const Flags& fl);

/// Refuses, before any work, an output path that names an input (scene, meshes, dry signal,
/// SOFA: same device and inode, symlinks followed), an existing non-regular file, another
/// output, or a folder that does not exist or is not writable. Main thread. Throws InputError
/// naming the flag.
void checkOutputs(const SceneDesc& scene, const Flags& fl);

}  // namespace dpc::demo
