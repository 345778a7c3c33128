#!/usr/bin/env python3
"""Writes the bad-file corpus read by ../corpus.rs. Run from anywhere:
    python3 crates/scallop-io/tests/corpus/generate.py
Output is deterministic (fixed zip timestamps), so re-running changes nothing."""

import math
import os
import struct
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))

V = [(1.5, -2.0, 0.25), (11.5, -2.0, 0.25), (1.5, 8.0, 0.25), (1.5, -2.0, 10.25)]
T = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def put(name, data):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def stl_ascii(v=V, t=T):
    s = "solid bad\n"
    for tri in t:
        s += "  facet normal 0 0 0\n    outer loop\n"
        for i in tri:
            s += "      vertex %s %s %s\n" % v[i]
        s += "    endloop\n  endfacet\n"
    return s + "endsolid bad\n"


def stl_binary(v=V, t=T, count=None):
    b = b"binary STL".ljust(80, b"\0")
    b += struct.pack("<I", len(t) if count is None else count)
    for tri in t:
        b += struct.pack("<3f", 0, 0, 0)
        for i in tri:
            b += struct.pack("<3f", *v[i])
        b += b"\0\0"
    return b


def obj(faces):
    return "".join("v %s %s %s\n" % p for p in V) + faces


def ply_ascii(body, header_extra=""):
    return (
        "ply\nformat ascii 1.0\n" + header_extra + "element vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n" + body
    )


PLY_VERTS = "".join("%s %s %s\n" % p for p in V)
PLY_FACES = "".join("3 %d %d %d\n" % f for f in T)


def model(objects, build, unit=""):
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<model%s xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">\n'
        " <resources>\n%s </resources>\n <build>\n%s </build>\n</model>\n" % (unit, objects, build)
    )


def mesh_object(oid, v=V, t=T, vertex_attrs=None):
    s = '  <object id="%d" type="model">\n   <mesh>\n    <vertices>\n' % oid
    for k, p in enumerate(v):
        attrs = vertex_attrs(k, p) if vertex_attrs else 'x="%s" y="%s" z="%s"' % p
        s += "     <vertex %s />\n" % attrs
    s += "    </vertices>\n    <triangles>\n"
    for tri in t:
        s += '     <triangle v1="%d" v2="%d" v3="%d" />\n' % tri
    return s + "    </triangles>\n   </mesh>\n  </object>\n"


RELS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n<Relationships '
    'xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship '
    'Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>'
    "</Relationships>\n"
)
TYPES = '<?xml version="1.0" encoding="UTF-8"?>\n<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types"/>\n'


def zipped(entries):
    path = os.path.join(HERE, "_tmp.zip")
    with zipfile.ZipFile(path, "w") as z:
        for name, data in entries:
            info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)
    with open(path, "rb") as f:
        data = f.read()
    os.remove(path)
    return data


def threemf(model_xml):
    return zipped([("[Content_Types].xml", TYPES), ("_rels/.rels", RELS), ("3D/3dmodel.model", model_xml)])


ITEM = '  <item objectid="1" />\n'

# --- STL ---
good_bin = stl_binary()
put("stl_empty.stl", b"")
put("stl_binary_truncated.stl", good_bin[: 84 + 50 * 2 + 17])
put("stl_binary_count_too_small.stl", stl_binary(count=3))
put("stl_binary_huge_count.stl", stl_binary(count=0xFFFFFFFF))
put("stl_binary_no_triangles.stl", stl_binary(t=[]))
put("stl_binary_short_header.stl", b"\0" * 40)
nan_bin = bytearray(good_bin)
nan_bin[84 + 50 * 2 + 12 + 12 * 1 + 4 : 84 + 50 * 2 + 12 + 12 * 1 + 8] = struct.pack("<f", math.nan)
put("stl_binary_nan.stl", bytes(nan_bin))
good = stl_ascii()
lines = good.split("\n")
put("stl_ascii_nan.stl", good.replace("vertex 11.5 -2.0 0.25", "vertex 11.5 NaN 0.25", 1))
put("stl_ascii_inf.stl", good.replace("vertex 1.5 8.0 0.25", "vertex 1.5 8.0 -inf", 1))
put("stl_ascii_missing_vertex.stl", "\n".join(lines[:4] + lines[5:]))
put("stl_ascii_two_coordinates.stl", good.replace("vertex 1.5 8.0 0.25", "vertex 1.5 8.0", 1))
put("stl_ascii_bad_number.stl", good.replace("vertex 1.5 8.0 0.25", "vertex 1.5 8,0 0.25", 1))
put("stl_ascii_not_utf8.stl", good.encode().replace(b"endloop", b"endl\xf6op", 1))
put("stl_ascii_empty_solid.stl", "solid empty\nendsolid empty\n")
put("stl_ascii_truncated.stl", good[: len(good) // 2])
put("stl_ascii_no_solid.stl", "facet normal 0 0 1\n outer loop\n")
put(
    "stl_ascii_all_degenerate.stl",
    stl_ascii(v=[(0, 0, 0), (1, 0, 0), (2, 0, 0), (0, 0, 0)], t=[(0, 1, 2), (0, 1, 3)]),
)

# --- OBJ ---
put("obj_index_zero.obj", obj("f 1 2 3\nf 0 2 3\n"))
put("obj_index_out_of_range.obj", obj("f 1 2 3\nf 1/1/1 2/1/1 5/1/1\n"))
put("obj_negative_out_of_range.obj", obj("f -1 -2 -3\nf -1 -2 -5\n"))
put("obj_nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
put("obj_not_utf8.obj", b"# caf\xe9 is fine in a comment\nv 0 0 0\nv 1 0 0\nv 0 1 \xff\nf 1 2 3\n")
put("obj_no_faces.obj", obj("vn 0 0 1\n"))
put("obj_bad_corner.obj", obj("f 1 2 3\nf 1 two 3\n"))
put("obj_two_corners.obj", obj("f 1 2\n"))
put("obj_binary_garbage.obj", bytes(range(256)) * 4)

# --- PLY ---
put("ply_too_few_vertex_lines.ply", ply_ascii("".join("%s %s %s\n" % p for p in V[:3]) + PLY_FACES))
put("ply_too_few_face_lines.ply", ply_ascii(PLY_VERTS + "".join("3 %d %d %d\n" % f for f in T[:3])))
put("ply_unknown_format.ply", ply_ascii(PLY_VERTS + PLY_FACES).replace("format ascii", "format binary_pdp_endian"))
put("ply_bad_index.ply", ply_ascii(PLY_VERTS + PLY_FACES.replace("3 1 2 3", "3 1 2 4")))
put("ply_nan.ply", ply_ascii(PLY_VERTS.replace("8.0", "nan") + PLY_FACES))
put("ply_not_utf8_header.ply", ply_ascii(PLY_VERTS + PLY_FACES).encode().replace(b"property float y", b"property fl\xf6at y"))
put("ply_no_face_element.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n")
put("ply_unknown_type.ply", ply_ascii(PLY_VERTS + PLY_FACES).replace("property float z", "property float128 z"))
put("ply_not_ply.ply", "solid x\n")
bin_header = (
    "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
).encode()
bin_body = b"".join(struct.pack("<3f", *p) for p in V) + b"".join(struct.pack("<B3i", 3, *f) for f in T)
put("ply_binary_truncated.ply", bin_header + bin_body[:-5])
put("ply_binary_trailing_bytes.ply", bin_header + bin_body + b"\0\0\0\0")
put("ply_binary_bad_index.ply", bin_header + bin_body[:-4] + struct.pack("<i", -7))

# --- 3MF ---
put("3mf_not_zip.3mf", "this is not a zip archive\n")
put("3mf_truncated_zip.3mf", threemf(model(mesh_object(1), ITEM))[:150])
put("3mf_without_model.3mf", zipped([("[Content_Types].xml", TYPES), ("_rels/.rels", RELS)]))
put("3mf_bad_index.3mf", threemf(model(mesh_object(1, t=T[:3] + [(1, 2, 9)]), ITEM)))
put(
    "3mf_nan_vertex.3mf",
    threemf(model(mesh_object(1, vertex_attrs=lambda k, p: 'x="%s" y="%s" z="%s"' % ((p[0], "NaN", p[2]) if k == 2 else p)), ITEM)),
)
put("3mf_missing_attribute.3mf", threemf(model(mesh_object(1, vertex_attrs=lambda k, p: 'x="%s" y="%s"' % p[:2]), ITEM)))
put("3mf_malformed_xml.3mf", threemf(model(mesh_object(1), ITEM).replace("</mesh>", "</mesj>")))
put("3mf_unknown_object.3mf", threemf(model(mesh_object(1), '  <item objectid="7" />\n')))
put("3mf_bad_transform.3mf", threemf(model(mesh_object(1), '  <item objectid="1" transform="1 0 0 1" />\n')))
put("3mf_unknown_unit.3mf", threemf(model(mesh_object(1), ITEM, unit=' unit="cubit"')))
put("3mf_no_build_items.3mf", threemf(model(mesh_object(1), "")))
put("3mf_not_utf8.3mf", threemf(model(mesh_object(1), ITEM).encode().replace(b"<build>", b"<b\xf6ild>")))
