"""Writes a Wavefront OBJ mesh for the scene generators in this folder.

write_obj(path, header, vertices, faces): header is written as is (comment lines ending in
a newline); vertices are (x, y, z) tuples in metres; faces are (material, triangles) pairs,
each triangle three 1-based vertex indices, written after a 'usemtl material' line.
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
