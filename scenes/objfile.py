"""Writes a Wavefront OBJ mesh for the scene generators in this folder.

write_obj(path, header, vertices, faces): header is written as is (comment lines ending in
a newline); vertices are (x, y, z) tuples in metres; faces are (material, triangles) pairs,
each triangle three 1-based vertex indices, written after a 'usemtl material' line.

ObjMesh builds such a mesh from quads and boxes whose corners are shared (edges are found by
vertex index, engine/diffraction.h, so a box's faces must share their corners).
"""


def write_obj(path, header, vertices, faces):
    with open(path, 'w') as f:
        f.write(header)
        for v in vertices:
            f.write('v %g %g %g\n' % v)
        for material, tris in faces:
            f.write('usemtl %s\n' % material)
            for t in tris:
                f.write('f %d %d %d\n' % t)


class ObjMesh:
    """Vertices (each position once) and faces, in the order they are added."""

    def __init__(self):
        self.vertices, self.faces, self._index = [], [], {}

    def vertex(self, p):
        """Index (1-based) of vertex p, shared by every face that uses it."""
        if p not in self._index:
            self.vertices.append(p)
            self._index[p] = len(self.vertices)
        return self._index[p]

    def quad(self, a, b, c, d, material):
        """Quad a-b-c-d, counter-clockwise seen from the side it faces: two triangles."""
        i = [self.vertex(p) for p in (a, b, c, d)]
        self.faces.append((material, [(i[0], i[1], i[2]), (i[0], i[2], i[3])]))

    def box(self, x0, x1, y0, y1, z0, z1, material, inward=False):
        """A closed box, faces -x, +x, -z, +z, +y, -y; outward (an obstacle) or inward (a
        room). material: one name, or six in that order."""
        sides = [((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),
                 ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),
                 ((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),
                 ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
                 ((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),
                 ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1))]
        names = material if isinstance(material, list) else [material] * 6
        for q, m in zip(sides, names):
            self.quad(*(q[::-1] if inward else q), m)

    def write(self, path, header):
        write_obj(path, header, self.vertices, self.faces)
