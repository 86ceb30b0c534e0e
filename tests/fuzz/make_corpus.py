#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (tests/fuzz/corpus/<target>/): small valid files of
every format the parsers read, each under 4 KB. Run from anywhere; rewrites the generated seeds."""
import gzip
import json
import struct
from pathlib import Path

CORPUS = Path(__file__).resolve().parent / "corpus"

# A unit cube: 8 corners, 12 outward triangles.
CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_T = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
          (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)]


def write(target, name, data):
    folder = CORPUS / target
    folder.mkdir(parents=True, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    assert len(data) < 4096, (target, name, len(data))
    (folder / name).write_bytes(data)


def normal(t):
    a, b, c = (CUBE_V[i] for i in t)
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def mask_4x4x4():
    # A 2x2x2 block of label 1 inside a 4x4x4 volume (a small non-empty mask).
    return bytes(1 if 1 <= x <= 2 and 1 <= y <= 2 and 1 <= z <= 2 else 0
                 for z in range(4) for y in range(4) for x in range(4))


def meshes():
    obj = "# unit cube\n" + "".join(f"v {x} {y} {z}\n" for x, y, z in CUBE_V)
    obj += "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in CUBE_T)
    write("mesh_obj", "cube.obj", obj)
    quads = "".join(f"v {x} {y} {z}\n" for x, y, z in CUBE_V) + "vn 0 0 1\n" + \
        "f 1//1 4//1 3//1 2//1\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
    write("mesh_obj", "cube_quads_normals.obj", quads)
    write("mesh_obj", "groups.obj", "o a\ng g1\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nusemtl m\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")

    stl = "solid cube\n"
    for t in CUBE_T:
        n = normal(t)
        stl += f" facet normal {n[0]} {n[1]} {n[2]}\n  outer loop\n"
        stl += "".join(f"   vertex {CUBE_V[i][0]} {CUBE_V[i][1]} {CUBE_V[i][2]}\n" for i in t)
        stl += "  endloop\n endfacet\n"
    stl += "endsolid cube\n"
    write("mesh_stl", "cube_ascii.stl", stl)
    binary = b"binary cube".ljust(80, b" ") + struct.pack("<I", len(CUBE_T))
    for t in CUBE_T:
        binary += struct.pack("<3f", *normal(t))
        for i in t:
            binary += struct.pack("<3f", *CUBE_V[i])
        binary += struct.pack("<H", 0)
    write("mesh_stl", "cube_binary.stl", binary)

    header = f"ply\nformat ascii 1.0\nelement vertex {len(CUBE_V)}\nproperty float x\nproperty float y\nproperty float z\n" \
             f"element face {len(CUBE_T)}\nproperty list uchar int vertex_indices\nend_header\n"
    write("mesh_ply", "cube_ascii.ply", header + "".join(f"{x} {y} {z}\n" for x, y, z in CUBE_V) +
          "".join(f"3 {a} {b} {c}\n" for a, b, c in CUBE_T))
    bheader = header.replace("format ascii 1.0", "format binary_little_endian 1.0")
    body = b"".join(struct.pack("<3f", *p) for p in CUBE_V) + b"".join(struct.pack("<B3i", 3, *t) for t in CUBE_T)
    write("mesh_ply", "cube_binary_le.ply", bheader.encode() + body)
    beheader = header.replace("format ascii 1.0", "format binary_big_endian 1.0")
    body = b"".join(struct.pack(">3f", *p) for p in CUBE_V) + b"".join(struct.pack(">B3i", 3, *t) for t in CUBE_T)
    write("mesh_ply", "cube_binary_be.ply", beheader.encode() + body)
    colored = f"ply\nformat ascii 1.0\ncomment colours and a quad\nelement vertex 4\nproperty double x\nproperty double y\n" \
              f"property double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 2\n" \
              f"property list uchar uint vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n" \
              f"0 1 1 9 9 9\n4 0 1 2 3\n3 0 2 3\n"
    write("mesh_ply", "quad_colours.ply", colored)

    off = f"OFF\n{len(CUBE_V)} {len(CUBE_T)} 0\n" + "".join(f"{x} {y} {z}\n" for x, y, z in CUBE_V) + \
        "".join(f"3 {a} {b} {c}\n" for a, b, c in CUBE_T)
    write("mesh_off", "cube.off", off)
    write("mesh_off", "cube_quads_comments.off",
          "OFF # header\n# a comment line\n8 6 12\n" + "".join(f"{x} {y} {z}\n" for x, y, z in CUBE_V) +
          "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n")
    write("mesh_off", "tetra_coff.off", "COFF\n4 4 6\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n"
          "0 0 1 9 9 9 255\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")


def nrrds():
    data = mask_4x4x4()
    base = "NRRD0004\n# seed\ntype: uint8\ndimension: 3\nsizes: 4 4 4\n"
    write("nrrd", "mask_raw.nrrd", (base + "space: right-anterior-superior\nspace directions: (1.5,0,0) (0,1.5,0) "
                                    "(0,0,2)\nspace origin: (-3,-3,-4)\nendian: little\nencoding: raw\n\n").encode() + data)
    write("nrrd", "mask_gzip.nrrd", (base + "space: left-posterior-superior\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n"
                                     "encoding: gzip\n\n").encode() + gzip.compress(data, mtime=0))
    write("nrrd", "mask_ascii_spacings.nrrd", base + "spacings: 0.5 0.5 1\nencoding: ascii\n\n" +
          " ".join(str(b) for b in data) + "\n")
    floats = struct.pack("<64f", *(float(b) * 2.5 for b in data))
    write("nrrd", "float_4d_single.nrrd", b"NRRD0005\ntype: float\ndimension: 4\nsizes: 1 4 4 4\n"
          b"kinds: none domain domain domain\nspacings: nan 1 1 1\nendian: little\nencoding: raw\n\n" + floats)
    shorts = struct.pack(">64h", *(int(b) * 300 for b in data))
    write("nrrd", "short_big_endian.nrrd", b"NRRD0004\ntype: short\ndimension: 3\nsizes: 4 4 4\nspace dimension: 3\n"
          b"space directions: (0,1,0) (1,0,0) (0,0,1)\nendian: big\nencoding: raw\n\n" + shorts)


def nifti1(datatype, bitpix, payload, sform=False, qform=False, dims=(4, 4, 4), pixdim=(1.0, 1.0, 1.0), units=2,
           slope=0.0, inter=0.0):
    h = bytearray(348)
    struct.pack_into("<i", h, 0, 348)
    struct.pack_into("<8h", h, 40, 3, *dims, 1, 1, 1, 1)
    struct.pack_into("<hh", h, 70, datatype, bitpix)
    struct.pack_into("<8f", h, 76, 1.0, *pixdim, 1, 0, 0, 0)
    struct.pack_into("<f", h, 108, 352.0)  # vox_offset
    struct.pack_into("<ff", h, 112, slope, inter)
    h[123] = units  # xyzt_units: mm
    struct.pack_into("<hh", h, 252, 1 if qform else 0, 1 if sform else 0)
    if qform:
        struct.pack_into("<6f", h, 256, 0.0, 0.0, 1.0, -2.0, -2.0, -2.0)  # quatern b c d, offsets
    if sform:
        struct.pack_into("<4f", h, 280, pixdim[0], 0, 0, -2)
        struct.pack_into("<4f", h, 296, 0, pixdim[1], 0, -2)
        struct.pack_into("<4f", h, 312, 0, 0, pixdim[2], -2)
    h[344:348] = b"n+1\0"
    return bytes(h) + b"\0\0\0\0" + payload


def nifti2(payload):
    h = bytearray(540)
    struct.pack_into("<i", h, 0, 540)
    h[4:12] = b"n+2\0\r\n\x1a\n"
    struct.pack_into("<hh", h, 12, 2, 8)  # uint8
    struct.pack_into("<8q", h, 16, 3, 4, 4, 4, 1, 1, 1, 1)
    struct.pack_into("<8d", h, 104, 1.0, 1.0, 1.0, 1.0, 1, 0, 0, 0)
    struct.pack_into("<q", h, 168, 544)  # vox_offset
    struct.pack_into("<i", h, 500, 2)  # xyzt_units
    return bytes(h) + b"\0\0\0\0" + payload


def niftis():
    data = mask_4x4x4()
    write("nifti", "mask_uint8.nii", nifti1(2, 8, data, pixdim=(1.5, 1.5, 2.0)))
    write("nifti", "mask_sform.nii", nifti1(2, 8, data, sform=True))
    write("nifti", "mask_qform_metres.nii", nifti1(2, 8, data, qform=True, pixdim=(0.001, 0.001, 0.002), units=1))
    write("nifti", "float32_scaled.nii", nifti1(16, 32, struct.pack("<64f", *(float(b) for b in data)), slope=2.0, inter=1.0))
    write("nifti", "int16.nii", nifti1(4, 16, struct.pack("<64h", *(int(b) * 7 for b in data))))
    write("nifti", "mask_nifti2.nii", nifti2(data))


def studio_messages():
    stroke = {"cmd": "add_stroke", "points_mm": [[0, 0, 0], [5, 0, 0], [10, 0, 1]]}
    messages = {
        "hello.json": {"cmd": "hello", "req": 1},
        "get_state.json": {"cmd": "get_state", "req": "a"},
        "ping.json": {"cmd": "ping"},
        "add_stroke.json": stroke,
        "move_stroke.json": {"cmd": "move_stroke", "id": 1, "offset_mm": [0, 1, 0]},
        "replace_design.json": {"cmd": "replace_design", "design": {"strokes": [{"id": 3, "points_mm": [[0, 0, 0], [1, 0, 0]]}],
                                                                     "control_points": [], "cuts": [], "next_id": 9}},
        "delete_stroke.json": {"cmd": "delete_stroke", "id": 1},
        "add_control_point.json": {"cmd": "add_control_point", "position_mm": [1, 2, 0], "langer_kPa": 10, "cross_kPa": 2},
        "set_control_point.json": {"cmd": "set_control_point", "id": 1, "langer_kPa": 5},
        "delete_control_point.json": {"cmd": "delete_control_point", "id": 1},
        "add_cut.json": {"cmd": "add_cut", "path_mm": [[0, 0, 1], [8, 0, 1]], "depth_mm": 2},
        "add_cut_kind.json": {"cmd": "add_cut", "kind": "scalpel", "path_mm": [[0, 0, 1], [8, 0, 1]], "depth_mm": 2},
        "delete_cut.json": {"cmd": "delete_cut", "id": 1},
        "reset_cuts.json": {"cmd": "reset_cuts"},
        "undo.json": {"cmd": "undo"},
        "redo.json": {"cmd": "redo", "req": [1, 2]},
        "save.json": {"cmd": "save", "file": "saved.json"},
        "load.json": {"cmd": "load", "file": "saved.json"},
        "export.json": {"cmd": "export", "format": "vtu", "file": "out.vtu"},
        "traversal.json": {"cmd": "save", "file": "../../etc/x.json"},
    }
    for name, message in messages.items():
        write("studio_message", name, json.dumps(message))
    # Several messages in one input, separated by the record separator byte (fuzz_studio_message.cpp).
    sequence = [stroke, {"cmd": "undo"}, {"cmd": "redo"}, {"cmd": "save", "file": "s.json"},
                {"cmd": "add_control_point", "position_mm": [0, 0, 0], "langer_kPa": 1, "cross_kPa": 1},
                {"cmd": "load", "file": "s.json"}, {"cmd": "undo"}]
    write("studio_message", "sequence.txt", "\x1e".join(json.dumps(m) for m in sequence))


if __name__ == "__main__":
    meshes()
    nrrds()
    niftis()
    studio_messages()
