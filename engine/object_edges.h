// The moving objects' diffracting edges (a game's crate, vehicle or door leaf as a scene
// object), for the paths round them (engine/edge_chain.h): each object's candidate edges
// found once in its own frame (engine/diffraction_edges.h candidateEdges, the object's mesh
// alone: an object's edges that rest on the floor count as free), and placed at the object's
// pose each frame: the way round an object across the line of sight.
//
// Internal to the engine. objectEdges: load time, allocates. placeObjectEdges: propagation
// thread between frames, allocates only the first time. No errors.
#pragma once

#include <vector>

#include "engine/diffraction.h"
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

}  // namespace dpc
