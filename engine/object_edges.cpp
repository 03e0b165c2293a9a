#include "engine/object_edges.h"

#include <algorithm>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/channel_path.h"
#include "engine/channel_turn.h"
#include "engine/diffraction_edges.h"
#include "engine/edge_chain.h"
#include "engine/edge_grid.h"
#include "engine/surface_bound.h"

namespace dpc {

std::vector<ObjectEdges> objectEdges(const std::vector<ObjectDesc>& objects) {
  std::vector<ObjectEdges> out(objects.size());
  for (size_t k = 0; k < objects.size(); ++k) {
    const Mesh& mesh = objects[k].mesh;
    const std::vector<uint32_t> surfaces = flatSurfaces(mesh);
    out[k].local = candidateEdges(mesh, surfaces);
    out[k].near = chainNeighbours(out[k].local);
    const size_t count =
        surfaces.empty() ? 0 : size_t(*std::max_element(surfaces.begin(), surfaces.end())) + 1;
    out[k].faces = narrowFaces(out[k].local, surfaceEdges(count, out[k].local));
    const auto& key = objects[k].trajectory;
    placeObjectEdges(out[k], key.empty() ? Pose{}
                                         : Pose{key.front().position, key.front().rotation});
  }
  return out;
}

void placeObjectEdges(ObjectEdges& o, const Pose& pose) {
  o.world.resize(o.local.size());
  for (size_t i = 0; i < o.local.size(); ++i) {
    const DiffractionEdge& l = o.local[i];
    DiffractionEdge& w = o.world[i];
    w = l;
    w.a = pose.rotation * l.a + pose.position;
    w.b = pose.rotation * l.b + pose.position;
    w.direction = pose.rotation * l.direction;
    w.face0 = pose.rotation * l.face0;
    w.normal0 = pose.rotation * l.normal0;
    w.surfaces = {kMovingObjects, kMovingObjects};
  }
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const DiffractionEdge& w : o.world) {
    lo = glm::min(lo, glm::min(w.a, w.b));
    hi = glm::max(hi, glm::max(w.a, w.b));
  }
  o.centre = o.world.empty() ? glm::vec3(0.f) : 0.5f * (lo + hi);
  o.radius = o.world.empty() ? 0.f : 0.5f * glm::distance(lo, hi);
}

bool nearLine(const ObjectEdges& o, const glm::vec3& source, const glm::vec3& L) {
  return !o.world.empty() &&
         segmentGap(source, L, o.centre, o.centre) - o.radius <= kChainSearch;
}

namespace {

/// The static edges whose segments pass within kChannelReach of o's sphere.
std::vector<uint32_t> staticEdgesNear(const std::vector<DiffractionEdge>& edges,
                                      const ObjectEdges& o) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < edges.size(); ++i)
    if (segmentGap(edges[i].a, edges[i].b, o.centre, o.centre) <= o.radius + kChannelReach)
      out.push_back(i);
  return out;
}

}  // namespace

std::vector<EdgePath> objectChannels(const Tracer& tracer, const std::vector<DiffractionEdge>& edges,
                                     const ObjectEdges& o, const glm::vec3& source,
                                     const glm::vec3& L) {
  std::vector<EdgePath> out;
  if (o.faces.empty()) return out;
  const std::vector<uint32_t> near = staticEdgesNear(edges, o);
  if (near.empty()) return out;
  const auto none = uint32_t(edges.size());
  for (const NarrowFace& f : o.faces)
    for (int way = 0; way < 2; ++way) {
      const DiffractionEdge& front = o.world[way == 0 ? f.a : f.b];
      const DiffractionEdge& back = o.world[way == 0 ? f.b : f.a];
      EdgePath p;
      // Straight, or seen along part of the edge where its point of least length is hidden (a
      // listener beside the doorway, the wall between: the undercut seen past the jamb), as
      // a static face's channels are.
      if ((channelPath(front, back, source, L, p) && legsFree(tracer, source, L, p)) ||
          visibleChannel(tracer, front, back, source, L, p)) {
        p.face = kMovingObjects;  // straight: often the reveal's slit too (markSlitOwners)
        out.push_back(p);
        continue;
      }
      const std::vector<uint32_t> entries =
          parallelNeighbours(edges, front, none, none, kChannelReach, kChannelNeighbours, near);
      const std::vector<uint32_t> exits =
          parallelNeighbours(edges, back, none, none, kChannelReach, kChannelNeighbours, near);
      if (!turnedChannel(tracer, edges, front, back, entries, exits, source, L, true, p)) continue;
      p.face = kMovingObjects;
      out.push_back(p);
    }
  return out;
}

}  // namespace dpc
