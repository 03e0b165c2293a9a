// The rendering pipeline shared by offline (--offline) and live playback: only the clock
// differs between them.
//
//   PropagationStage (propagation thread)          AudioStage (audio thread)
//   world state -> Simulation frame -> energy      pops prepared IrSet, convolves every
//   responses -> pressure IRs -> non-uniform       source's dry signal (non-uniform partitions,
//   partition + FFT into a recycled IrSet          crossfade old/new IR at every partition
//                          ----- IrSet* ------>    level), mixes into the output bus
//                          <--- spent IrSet* ----
//
// IrSet: the partitioned spectra of every source's IR (numOutputs channels each) plus the frame
// it came from. Sets are allocated up front in a pool by the PropagationStage; the audio side
// only borrows them and hands each back once no partition level uses it.
// The stages share the scene, the dry signals and the convolver layout (std::shared_ptr to
// const), so each stays valid as long as any holder lives.
#pragma once

#include "runtime/audio_stage.h"
#include "runtime/dry_signals.h"
#include "runtime/propagation_stage.h"
