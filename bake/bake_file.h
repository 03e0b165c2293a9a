// The bake file: HDF5 (Debian libhdf5-dev, the C API), one writer. docs/bake-format.md
// describes every dataset, shape, unit and attribute; this is its one reader and writer.
//
// Crash consistency: a probe is committed by writing its slices of every per-probe dataset,
// then its entry of /probes/done, then flushing the file (H5Fflush), so a bake killed at any
// point between commits leaves a file whose done mask names exactly the probes stored. The
// root attribute `complete` is 0 until every probe is done.
// Control thread of the writing process only; allocates; every error is an InputError naming
// the file and the dataset or attribute (a truncated or foreign file, a shape that does not
// match the header) or a std::runtime_error for a failed write.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <string>
#include <vector>

#include "bake/probe_bake.h"
#include "bake/probe_grid.h"
#include "scene/scene.h"

namespace dpc::bake {

/// Format name and version written to and required from the root attributes.
inline constexpr const char* kBakeFormat = "dpc-bake";
inline constexpr int kBakeFormatVersion = 3;
/// The `sh_convention` attribute: channel order and normalisation of `sh_energy`.
inline constexpr const char* kShConvention = "ACN/SN3D";

/// Everything a bake is fixed by: the scene, the grid and the settings.
struct BakeHeader {
  std::string scenePath;  ///< the scene file, absolute
  uint64_t meshHash = 0;  ///< sceneHash(scene)
  uint64_t seed = 1;      ///< the scene's propagation seed
  GridRequest grid;
  BakeSettings settings;
  ProbeGrid probes;                  ///< kept probes and the skipped counts
  std::vector<glm::vec3> sources;    ///< static source positions, metres
  ProbeShape shape;
};

/// FNV-1a over what a bake depends on in the scene: the static mesh (vertices, triangles,
/// material indices), every material's absorption and scattering, the sources' positions at
/// t = 0 and the propagation physics (order, speed of sound, air). A bake is refused for any
/// scene whose hash differs. Any thread; no allocation.
uint64_t sceneHash(const SceneDesc& scene);

class BakeFile {
 public:
  /// Creates `path` (truncating it) with every dataset sized for the header, no probe done,
  /// `complete` 0. Messages name the file `displayPath` (e.g. the name a temporary file is
  /// renamed to).
  static BakeFile create(const std::string& path, const std::string& displayPath,
                         const BakeHeader& header);
  /// Opens an existing bake for reading and (writable) committing, validating its format,
  /// version, attributes and every dataset's shape against them.
  static BakeFile open(const std::string& path, bool writable);

  BakeFile(BakeFile&&) noexcept;
  BakeFile& operator=(BakeFile&&) noexcept;
  ~BakeFile();

  const BakeHeader& header() const;
  const std::string& path() const;
  /// /probes/done: 1 where the probe is stored.
  std::vector<uint8_t> done() const;
  bool complete() const;

  /// Writes probe `probe`'s arrays, marks it done and flushes.
  void commit(size_t probe, const ProbeResult& result);
  /// Wall time spent in commit() so far, seconds (the writer's share of a bake's cost).
  double commitSeconds() const;
  /// Sets `complete` to 1 and flushes (call when done() is all ones).
  void markComplete();

  /// A whole float dataset (e.g. "parameters"), row-major as documented.
  std::vector<float> readAll(const std::string& dataset) const;

 private:
  struct Impl;
  explicit BakeFile(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dpc::bake
