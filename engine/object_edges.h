// The moving objects' diffracting edges (a game's crate, vehicle or door leaf as a scene
// object), for the paths round them (engine/edge_chain.h): each object's candidate edges
// found once in its own frame (engine/diffraction_edges.h candidateEdges, the object's mesh
// alone: an object's edges that rest on the floor count as free), and placed at the object's
// pose each frame: the way round an object across the line of sight, and the gaps along its
// narrow faces where they turn round a door stop.
//
// Internal to the engine. objectEdges: load time, allocates. placeObjectEdges: propagation
// thread between frames, allocates only the first time. No errors.
#pragma once

#include <vector>

#include "engine/diffraction.h"
#include "engine/edge_path.h"
#include "engine/tracer.h"
#include "scene/scene.h"

namespace dpc {

/// Per object (scene order), its edges (ObjectEdges, engine/diffraction.h), placed at its first
/// keyframe's pose (the tracer's starting pose).
std::vector<ObjectEdges> objectEdges(const std::vector<ObjectDesc>& objects);

/// Places o's edges at `pose` (position in metres, unit rotation), and the sphere round them.
void placeObjectEdges(ObjectEdges& o, const Pose& pose);

/// True when o's placed edges may lie within kChainSearch of the segment from source to L (m):
/// its sphere does. Any thread.
bool nearLine(const ObjectEdges& o, const glm::vec3& source, const glm::vec3& L);

/// The channels along o's narrow faces (engine/channel_path.h channelPath): straight ones whose
/// legs are free or that are seen along part of their edge (visibleChannel), and those that turn at a mouth round the static mesh's edges (`edges`) near it
/// (engine/channel_turn.h turnedChannel: an object door leaf closed against a door stop in the
/// mesh, its gaps L-shaped). A straight one is often the same slit as the reveal's own channel
/// with the leaf across it (engine/gap_probe.h GapShape::depth): markSlitOwners keeps one. Each
/// path's face is kMovingObjects; their gaps not yet probed (findSlits). Any thread (tracer
/// queries only); allocates; one pass over `edges` per call for the ones near o, then
/// turnedChannel's rays per face whose straight channel is blocked.
std::vector<EdgePath> objectChannels(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                                     const ObjectEdges& o, const glm::vec3& source,
                                     const glm::vec3& L);

}  // namespace dpc
