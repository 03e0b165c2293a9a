#include "engine/object_edges.h"

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
}

}  // namespace dpc
