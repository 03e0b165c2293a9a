"""The bad-input suite's setups (tests/bad_input/run.py): each returns, or is, a function of the
case's folder that damages one thing in its copy of the shoebox scene."""
import json, os, subprocess, sys

DPC_BAKE = None  # dpc-bake, beside dpc-demo (run.py's main sets it)


def scene_with(**edits):
    """Returns a function that edits the shoebox JSON: keys are dotted paths, values new values."""
    def apply(d):
        s = json.load(open(os.path.join(d, "shoebox.json")))
        for path, value in edits.items():
            node, keys = s, path.split(".")
            for k in keys[:-1]:
                node = node[int(k)] if isinstance(node, list) else node[k]
            last = keys[-1]
            if isinstance(node, list):
                node[int(last)] = value
            else:
                node[last] = value
        json.dump(s, open(os.path.join(d, "shoebox.json"), "w"))
    return apply


def without(key, **edits):
    """Like scene_with, after removing the top-level `key` from the shoebox JSON."""
    def apply(d):
        path = os.path.join(d, "shoebox.json")
        s = json.load(open(path))
        del s[key]
        json.dump(s, open(path, "w"))
        scene_with(**edits)(d)
    return apply


def write(name, text, mode="w"):
    def apply(d):
        with open(os.path.join(d, name), mode) as f:
            f.write(text)
    return apply


def obj_with(line):
    return lambda d: open(os.path.join(d, "shoebox.obj"), "a").write(line + "\n")


def nothing(d):
    pass


def write_text(edit):
    """Edits the shoebox JSON as text (for what json.dump cannot write, e.g. a repeated key)."""
    def apply(d):
        path = os.path.join(d, "shoebox.json")
        text = open(path).read()
        open(path, "w").write(edit(text))
    return apply


def two_listeners(first_name):
    """Replaces the listener by two listeners, the first named `first_name`."""
    return without("listener", listeners=[
        {"name": first_name, "position": [5, 1.6, 3.5], "radius": 0.5},
        {"name": "b", "position": [6, 1.6, 3.5], "radius": 0.5}])


def bake_file(edit=None, damage=None):
    """Bakes the shoebox (after `edit`, undone afterwards) into bake.h5 with dpc-bake, then
    applies `damage` to the file's path: the bake dpc-demo --bake is given."""
    def apply(d):
        scene = os.path.join(d, "shoebox.json")
        original = open(scene).read()
        if edit:
            edit(d)
        subprocess.run([DPC_BAKE, "shoebox.json", "--out", "bake.h5", "--spacing", "2", "--rays",
                        "100", "--frames", "4", "--threads", "1"], cwd=d, check=True,
                       capture_output=True)
        open(scene, "w").write(original)
        if damage:
            damage(os.path.join(d, "bake.h5"))
    return apply


def truncate_half(path):
    os.truncate(path, os.path.getsize(path) // 2)


def read_only(name, mode=0o444):
    """Writes a file NAME (an existing output the run must not replace) with this mode."""
    def apply(d):
        write(name, "an existing output\n")(d)
        os.chmod(os.path.join(d, name), mode)
    return apply


def open_to_nobody(d):
    """Lets user nobody (AS_NOBODY cases) read the case's files and write in its folder."""
    os.chmod(d, 0o777)
    for root, dirs, files in os.walk(d):
        for name in dirs:
            os.chmod(os.path.join(root, name), 0o755)


def read_only_folder(name):
    """A folder NAME with no write bits (mode 555): refused for root too, whom access() lets
    write into it."""
    def apply(d):
        os.mkdir(os.path.join(d, name))
        os.chmod(os.path.join(d, name), 0o555)
    return apply


def fifo(name):
    return lambda d: os.mkfifo(os.path.join(d, name))


def symlink(target, name):
    return lambda d: os.symlink(target, os.path.join(d, name))


def mkdir(name):
    return lambda d: os.mkdir(os.path.join(d, name))


def sparse(name, size):
    def apply(d):
        with open(os.path.join(d, name), "wb") as f:
            f.truncate(size)
    return apply


def float_wav(name, rate, samples):
    """Writes a mono IEEE-float WAV (format 3) holding `samples`, and points source 0 at it."""
    import struct
    def apply(d):
        data = struct.pack(f"<{len(samples)}f", *samples)
        fmt = struct.pack("<HHIIHH", 3, 1, rate, rate * 4, 4, 32)
        body = b"WAVE" + b"fmt " + struct.pack("<I", len(fmt)) + fmt + b"data" + struct.pack("<I", len(data)) + data
        with open(os.path.join(d, name), "wb") as f:
            f.write(b"RIFF" + struct.pack("<I", len(body)) + body)
        scene_with(**{"sources.0.signal": name})(d)
    return apply


def gltf_level(edit, name="shoebox.glb", objects=None, drop_bin=False, buffer_uri=None):
    """Writes the shoebox's OBJ as a glTF level NAME (node "room", one primitive per material
    run; scenes/gltffile.py), lets edit(g) break it before it is saved, and points the scene's
    mesh (and "objects", if given) at it. drop_bin: a .gltf whose .bin buffer is then removed;
    buffer_uri: a .gltf whose buffer is then pointed at this file instead."""
    def apply(d):
        sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                        "scenes"))
        from gltffile import Gltf, read_obj
        g = Gltf()
        runs = read_obj(os.path.join(d, "shoebox.obj"))
        g.node("room", mesh=g.mesh("room", [(g.material(m), p, t) for m, p, t in runs]))
        edit(g)
        g.save(os.path.join(d, name))
        if drop_bin:
            os.remove(os.path.join(d, name[:-5] + ".bin"))
        if buffer_uri:
            doc = json.load(open(os.path.join(d, name)))
            doc["buffers"][0]["uri"] = buffer_uri
            json.dump(doc, open(os.path.join(d, name), "w"))
        edits = {"mesh": name} if objects is None else {"mesh": name, "objects": objects}
        scene_with(**edits)(d)
    return apply


def gltf_set(path, value):
    """An edit of the glTF JSON: path is a tuple of keys and indices."""
    def edit(g):
        node = g.doc
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = value
    return edit


def gltf_door(interpolation="LINEAR", node=None):
    """Adds a door node (one triangle, material "walls") and a rotation animation of `node`
    (default: the door) with the given sampler interpolation."""
    def edit(g):
        door = g.node("door", mesh=g.mesh("door", [(0, [(0, 0, 0), (0, 2, 0), (0, 2, 1)],
                                                    [(0, 1, 2)])]), translation=[5, 0, 3])
        keys = [(0, 0, 0, 1), (0, 0.7071068, 0, 0.7071068)]
        if interpolation == "CUBICSPLINE":  # in-tangent, value, out-tangent per key
            keys = [v for k in keys for v in ((0, 0, 0, 0), k, (0, 0, 0, 0))]
        g.animation("swing", [(door if node is None else node, "rotation", [0, 1], keys,
                               interpolation)])
    return edit


def no_edit(g):
    pass


def gltf_nan_vertex(g):
    """Adds node "bad" whose mesh's second vertex is NaN (as an exporter bug would write)."""
    bad = g.mesh("bad", [(0, [(0, 0, 0), (float("nan"), 1, 0), (1, 1, 0)], [(0, 1, 2)])])
    g.node("bad", mesh=bad)


def gltf_door_on_node_9(g):
    """The door's animation aimed at node 9, which the file does not have."""
    gltf_door()(g)
    g.doc["animations"][0]["channels"][0]["target"]["node"] = 9


def steps(*setups):
    """The setups one after the other."""
    def apply(d):
        for setup in setups:
            setup(d)
    return apply


def gltf_index_out_of_range(d):
    """A .gltf level whose first triangle index is 1,000,000 (the accessor has a few vertices):
    assimp drops the face with only a warning."""
    import struct
    gltf_level(no_edit, "shoebox.gltf")(d)
    doc = json.load(open(os.path.join(d, "shoebox.gltf")))
    view = doc["bufferViews"][doc["accessors"][1]["bufferView"]]
    with open(os.path.join(d, "shoebox.bin"), "r+b") as f:
        f.seek(view.get("byteOffset", 0))
        f.write(struct.pack("<I", 1000000))


def gltf_deep_nesting(d):
    """A .gltf level whose JSON nests 200,000 arrays (the parsers recurse once per level)."""
    n = 200000
    write("shoebox.gltf", '{"asset":{"version":"2.0"},"x":' + "[" * n + "]" * n + "}")(d)
    scene_with(mesh="shoebox.gltf")(d)


def gltf_node_chain(depth):
    """The room's node under a chain of depth - 1 group nodes (a node tree `depth` deep)."""
    def edit(g):
        child = 0
        for k in range(depth - 1):
            child = g.node("group%d" % k, children=[child])
    return edit


def glb_bytes(offset, value):
    """The shoebox .glb level with the 32-bit little-endian word at `offset` set to `value`
    (12: the JSON chunk's length)."""
    import struct

    def apply(d):
        gltf_level(no_edit)(d)
        path = os.path.join(d, "shoebox.glb")
        data = bytearray(open(path, "rb").read())
        data[offset:offset + 4] = struct.pack("<I", value)
        open(path, "wb").write(bytes(data))
    return apply


def fbx_level(unit_scale):
    """An ASCII FBX 7.4 level (a floor quad, material "floor") whose UnitScaleFactor is
    `unit_scale` centimetres per unit, as the scene's mesh."""
    text = """; FBX 7.4.0 project file
FBXHeaderExtension:  {
	FBXHeaderVersion: 1003
	FBXVersion: 7400
}
GlobalSettings:  {
	Version: 1000
	Properties70:  {
		P: "UpAxis", "int", "Integer", "",1
		P: "UpAxisSign", "int", "Integer", "",1
		P: "FrontAxis", "int", "Integer", "",2
		P: "FrontAxisSign", "int", "Integer", "",1
		P: "CoordAxis", "int", "Integer", "",0
		P: "CoordAxisSign", "int", "Integer", "",1
		P: "UnitScaleFactor", "double", "Number", "",%s
	}
}
Objects:  {
	Geometry: 1000, "Geometry::floor", "Mesh" {
		Vertices: *12 {
			a: 0,0,0,0,0,700,1000,0,700,1000,0,0
		}
		PolygonVertexIndex: *4 {
			a: 0,1,2,-4
		}
		LayerElementMaterial: 0 {
			Version: 101
			MappingInformationType: "AllSame"
			ReferenceInformationType: "IndexToDirect"
			Materials: *1 {
				a: 0
			}
		}
		Layer: 0 {
			Version: 100
			LayerElement:  {
				Type: "LayerElementMaterial"
				TypedIndex: 0
			}
		}
	}
	Model: 2000, "Model::floor", "Mesh" {
		Version: 232
	}
	Material: 3000, "Material::floor", "" {
		Version: 102
	}
}
Connections:  {
	C: "OO",1000,2000
	C: "OO",2000,0
	C: "OO",3000,2000
}
""" % unit_scale

    def apply(d):
        write("level.fbx", text)(d)
        scene_with(mesh="level.fbx")(d)
    return apply
