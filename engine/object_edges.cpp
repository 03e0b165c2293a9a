#include "engine/object_edges.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/diffraction_edges.h"
#include "engine/edge_chain.h"
#include "engine/surface_bound.h"

namespace dpc {

std::vector<ObjectEdges> objectEdges(const std::vector<ObjectDesc>& objects) {
  std::vector<ObjectEdges> out(objects.size());
  for (size_t k = 0; k < objects.size(); ++k) {
    const Mesh& mesh = objects[k].mesh;
    out[k].local = candidateEdges(mesh, flatSurfaces(mesh));
    out[k].near = chainNeighbours(out[k].local);
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

}  // namespace dpc
