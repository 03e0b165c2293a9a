// What one run of dpc-bake bakes: a fresh bake's scene, probes and header, or what a resumed
// bake's file still needs (its probes not stored, or damaged). Planning refuses, before any
// file is created or changed: a grid over the limits of apps/bake/estimate.h unless --force
// (the grid's candidate count at once, before the probes are placed; then the placed probes'
// estimate), and a resume whose scene or settings differ from the bake's in any group of the
// settings hash (bake/settings_hash.h), naming the group (or `seed`, `probe_radius_m`,
// `ir_length_s`). Each rank's main thread; allocates; errors as InputError.
#pragma once

#include <memory>
#include <vector>

#include "apps/bake/estimate.h"
#include "apps/bake/options.h"
#include "bake/bake_layout.h"
#include "bake/probe_bake.h"

namespace dpc::bake {

struct Plan {
  SceneDesc scene;
  BakeHeader header;
  std::vector<size_t> todo;  ///< probes this run bakes
  std::vector<size_t> waveTodo;  ///< sources whose wave band this run simulates (rank 0)
  size_t alreadyDone = 0;    ///< probes stored (and verified) before this run
  bool wasComplete = false;  ///< a resumed file said complete (its map is rewritten, or its
                             ///< damaged probes baked again)
  std::unique_ptr<ProbeBaker> baker;  ///< over `scene` (so the plan is not moved once made)
  BakeEstimate estimate;              ///< rank 0: the run's cost (seconds measured)
  WaveEstimate wave;                  ///< the wave band's simulations in this run (waveTodo)
};

/// Plans a fresh bake into `plan` (in place: the baker refers to plan.scene). `measure`: time
/// one frame and check the limits (rank 0; the other ranks meet the same input).
void planFresh(const Options& o, int processes, bool measure, Plan& plan);
/// Plans the rest of the bake o.resume. Rank 0 (`report`) prints one line when probes the file
/// marked done fail their checksums (they are baked again).
void planResume(const Options& o, int processes, bool report, Plan& plan);

}  // namespace dpc::bake
