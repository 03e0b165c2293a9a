// Impulse responses as a SOFA file (AES69-2022), convention GeneralFIR 1.0, written with
// netCDF-4 (HDF5 storage, which libmysofa and the netCDF/HDF5 tools read).
//
// Dimensions: M measurements (one per source), R receivers (the output channels: ears,
// loudspeaker feeds or Ambisonic channels), N samples, E = 1 emitter, I = 1, C = 3.
// Variables: Data.IR [M R N] (double; the IR's float samples, exactly), Data.SamplingRate [I] (Hz),
// Data.Delay [I R] (samples, zero: the delays are in the IRs), SourcePosition [M C],
// ListenerPosition, ListenerView, ListenerUp [I C], ReceiverPosition [R C I], EmitterPosition
// [E C I], all cartesian, metres, in SOFA's global frame (x, y horizontal, z up; the caller
// converts). Global attributes: the convention's required ones (Conventions "SOFA",
// SOFAConventions "GeneralFIR", DataType "FIR", RoomType, Title, dates, API and author).
// Reference: AES69-2022, "AES standard for file exchange - Spatial acoustic data file format".
//
// Control thread or an offline render thread: allocates, makes system calls; throws
// InputError(path, "", reason) when the file cannot be written (no partial file remains).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "common/impulse_response.h"
#include "common/output_file.h"

namespace dpc::audio {

using Vec3d = std::array<double, 3>;

struct SofaIrs {
  int sampleRate = 0;  ///< Hz
  /// One per measurement, its channels the receivers: every measurement the same receivers,
  /// every receiver the same length (>= 1 sample).
  std::vector<ImpulseResponse> irs;
  std::vector<Vec3d> sourcePositions;    ///< [measurement], metres
  std::vector<Vec3d> receiverPositions;  ///< [receiver], metres relative to the listener
  Vec3d listenerPosition{};              ///< metres
  Vec3d listenerView{1, 0, 0};           ///< unit vector the listener faces
  Vec3d listenerUp{0, 0, 1};             ///< unit vector
  std::string roomType = "reverberant";  ///< AES69 RoomType: "free field", "reverberant", ...
  std::string title;
  std::string comment;  ///< what the receivers are (e.g. "AmbiX ACN/SN3D order 3")
};

/// Writes `irs` to a complete temporary next to `path`, returned for the caller to commit
/// (OutputSet, common/output_file.h). Throws InputError(path, "", ...) on inconsistent shapes
/// or a netCDF error.
TempOutputFile stageSofa(const std::string& path, const SofaIrs& irs);

}  // namespace dpc::audio
