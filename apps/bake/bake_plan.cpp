#include "apps/bake/bake_plan.h"

#include <cstdio>
#include <filesystem>

#include "apps/bake/bake_wave.h"
#include "bake/bake_file.h"
#include "bake/settings_hash.h"
#include "common/input_error.h"
#include "scene/limits.h"
#include "scene/trajectory.h"

namespace dpc::bake {
namespace {

/// Where a frame is timed: the scene's first listener at t = 0, a place a user stands.
glm::vec3 timingPosition(const SceneDesc& scene) {
  return listenerPositionAt(scene.listeners[0], 0.0);
}

/// The probes' candidates (a grid, a box lattice or the list), checked against the limits at
/// once when there are more of them than a bake may have unforced: each is an upper bound of
/// the probes, so the estimate printed is one too.
std::vector<glm::vec3> candidatesOf(const Options& o, const Plan& plan, bool measure) {
  std::vector<glm::vec3> c = o.probes.empty() ? gridCandidates(plan.scene, plan.header.grid)
                                              : readProbeList(o.probes);
  if (c.size() <= kMaxProbesUnforced || o.force) return c;
  if (!measure)  // rank 0 says why; the others only stop before placing the candidates
    throw InputError("command line", "--spacing", "over the probe limit");
  BakeEstimate e = estimateBake(c.size(), c.size(), plan.header.shape, plan.header.settings,
                                plan.baker->timeFrame(timingPosition(plan.scene)),
                                plan.estimate.processes);
  e.upperBound = true;
  checkLimits(e, o.force, o.probes.empty() ? "--spacing" : "--probes");
  return c;  // not reached: more candidates than kMaxProbesUnforced are over the limit
}

}  // namespace

void planFresh(const Options& o, int processes, bool measure, Plan& plan) {
  plan.scene = loadScene(o.scene);
  BakeHeader& h = plan.header;
  h.scenePath = std::filesystem::absolute(o.scene).string();
  h.seed = plan.scene.propagation.seed;
  h.settings = o.settings;
  if (!o.raysGiven) h.settings.rays = plan.scene.propagation.raysPerFrame;
  h.settings.irLength = plan.scene.propagation.irLength;
  h.grid = o.grid;
  h.grid.radiusM = plan.scene.listeners[0].radius;
  if (!o.probes.empty()) h.grid.spacingM = h.grid.heightM = 0.0;  // a list: no grid
  for (const SourceDesc& s : plan.scene.sources) h.sources.push_back(sourcePositionAt(s, 0.0));
  h.shape = probeShape(plan.scene, h.settings);
  h.wave = waveLayout(plan.scene, h.settings.irLength);
  if (h.wave.enabled) {
    for (size_t s = 0; s < h.sources.size(); ++s) plan.waveTodo.push_back(s);
    plan.wave = estimateWave(plan.scene, h.settings.irLength);  // a grid too large: no file
  }
  plan.baker = std::make_unique<ProbeBaker>(plan.scene, h.settings);
  plan.estimate.processes = processes;
  const std::vector<glm::vec3> candidates = candidatesOf(o, plan, measure);
  h.probes = o.probes.empty()
                 ? placeProbes(plan.scene, candidates, h.grid.radiusM, o.scene, gridField(h.grid))
                 : placeProbes(plan.scene, candidates, h.grid.radiusM, o.probes, "--probes");
  h.hashes = settingsHash(plan.scene, h.settings, h.probes.positions);
  for (size_t p = 0; p < h.probes.positions.size(); ++p) plan.todo.push_back(p);
  if (!measure) return;
  plan.estimate = estimateBake(plan.todo.size(), plan.todo.size(), h.shape, h.settings,
                               plan.baker->timeFrame(timingPosition(plan.scene)), processes);
  plan.estimate.bytes += waveBandBytes(h.probes.positions.size(), h.sources.size(), h.wave);
  checkLimits(plan.estimate, o.force, o.probes.empty() ? "--spacing" : "--probes");
}

namespace {

/// Refuses a resume whose scene gives other settings hashes than the bake's: the attribute
/// of the group (or the setting itself where the file records it) and what changed.
void checkResumable(const std::string& bake, const std::string& scenePath, const Plan& plan) {
  const BakeHeader& h = plan.header;
  BakeSettings settings = h.settings;
  settings.irLength = plan.scene.propagation.irLength;
  const int g =
      firstDifference(h.hashes, settingsHash(plan.scene, settings, h.probes.positions), false);
  if (g < 0) return;
  const std::string tail = "; --resume needs the scene the bake was started with";
  const PropagationSettings& p = plan.scene.propagation;
  if (g == int(SettingGroup::kSampling) && h.seed != p.seed)
    throw InputError(bake, "seed",
                     "the bake was started with seed " + std::to_string(h.seed) + ", " +
                         scenePath + " has " + std::to_string(p.seed) + tail);
  if (g == int(SettingGroup::kListener))
    throw InputError(bake, "probe_radius_m",
                     "the bake's probes have radius " + valueText(h.grid.radiusM) + " m, " +
                         scenePath + "'s first listener " +
                         valueText(plan.scene.listeners[0].radius) + " m" + tail);
  if (g == int(SettingGroup::kResponse))
    throw InputError(bake, "ir_length_s",
                     "the bake's responses are " + valueText(h.settings.irLength) +
                         " s long, " + scenePath + "'s ir_length is " +
                         valueText(p.irLength) + " s" + tail);
  const SettingGroupInfo& info = kSettingGroupInfo[size_t(g)];
  throw InputError(bake, info.attribute,
                   std::string("the ") + info.what + " of " + scenePath +
                       " differ from the bake's (the scene changed since the bake started)" +
                       tail);
}

}  // namespace

void planResume(const Options& o, int processes, bool report, Plan& plan) {
  std::vector<uint8_t> done, waveDone;
  size_t damaged = 0;
  std::string damage, waveDamage;
  {
    const BakeFile file = BakeFile::open(o.resume, BakeFile::Access::kInspect);
    plan.header = file.header();
    plan.wasComplete = file.complete();
    done = file.done();
    damaged = file.damaged().size();
    damage = file.damageReport();
    waveDone = file.waveDone();
    waveDamage = file.waveDamageReport();
  }
  const std::string scenePath = o.scene.empty() ? plan.header.scenePath : o.scene;
  plan.scene = loadScene(scenePath);
  checkResumable(o.resume, scenePath, plan);
  if (report && damaged > 0)
    std::fprintf(stderr,
                 "dpc-bake: %s: %zu probes marked done fail their checksums (first: %s); "
                 "baking them again\n",
                 o.resume.c_str(), damaged, damage.c_str());
  if (report && !waveDamage.empty())
    std::fprintf(stderr, "dpc-bake: %s: %s; simulating that wave band again\n", o.resume.c_str(),
                 waveDamage.c_str());
  for (size_t s = 0; s < waveDone.size(); ++s)
    if (!waveDone[s]) plan.waveTodo.push_back(s);
  if (!plan.waveTodo.empty()) {
    plan.wave = estimateWave(plan.scene, plan.header.settings.irLength);
    plan.wave.simulations = plan.wave.simulations / plan.scene.sources.size() *
                            plan.waveTodo.size();
  }
  plan.header.settings.threads = o.settings.threads;
  for (size_t p = 0; p < done.size(); ++p)
    if (!done[p]) plan.todo.push_back(p);
  plan.alreadyDone = done.size() - plan.todo.size();
  plan.baker = std::make_unique<ProbeBaker>(plan.scene, plan.header.settings);
  plan.estimate = estimateBake(plan.todo.size(), done.size(), plan.header.shape,
                               plan.header.settings,
                               report && !plan.todo.empty()
                                   ? plan.baker->timeFrame(timingPosition(plan.scene))
                                   : 0.0,
                               processes);
  plan.estimate.bytes += waveBandBytes(done.size(), plan.header.sources.size(), plan.header.wave);
}

}  // namespace dpc::bake
