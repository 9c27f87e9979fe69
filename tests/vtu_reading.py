"""Reading VTU polyhedron files independently of vemkit (the 3D file and CLI tests): every DataArray
decoded from its base64 text, the face streams turned into sorted canonical vertex cycles per cell."""

import numpy as np

from vemkit.mesh.polyhedral_build import csr_rows


def outward_cycles(mesh, c):
    rows = csr_rows(mesh.face_offsets, mesh.face_vertices)
    out = []
    for s in mesh.cell_face_list(c):
        f = rows[s if s >= 0 else -s - 1]
        f = f[f >= 0]
        out.append(canonical(f if s >= 0 else f[::-1]))
    return sorted(out)


def canonical(cycle):
    cycle = [int(v) for v in cycle]
    i = cycle.index(min(cycle))
    return tuple(cycle[i:] + cycle[:i])


def vtu_arrays(path):
    """Every DataArray of a binary VTU file (UInt64 headers), decoded independently of vemkit."""
    import base64
    import re
    import zlib

    kinds = {"Float64": np.float64, "Int64": np.int64, "UInt8": np.uint8}
    text_of_file = path.read_text()
    compressed = 'compressor="vtkZLibDataCompressor"' in text_of_file
    out = {}
    for kind, name, text in re.findall(r'<DataArray type="(\w+)" Name="(\w+)"[^>]*>([^<]*)</DataArray>', text_of_file):
        if not compressed:
            raw = base64.b64decode(text)
            out[name] = np.frombuffer(raw[8 : 8 + int(np.frombuffer(raw[:8], np.uint64)[0])], kinds[kind])
            continue
        blocks = int(np.frombuffer(base64.b64decode(text[:12])[:8], np.uint64)[0])  # 8 bytes: 12 base64 characters
        size = 8 * (3 + blocks)
        header_chars = 4 * ((size + 2) // 3)
        header = np.frombuffer(base64.b64decode(text[:header_chars])[:size], np.uint64)
        data = base64.b64decode(text[header_chars:])
        parts, at = [], 0
        for packed in header[3 : 3 + blocks]:
            parts.append(zlib.decompress(data[at : at + int(packed)]))
            at += int(packed)
        out[name] = np.frombuffer(b"".join(parts), kinds[kind])
    return out


def stream_cycles(faces, faceoffsets):
    cells, start = [], 0
    for end in faceoffsets:
        count, at, cycles = faces[start], start + 1, []
        for _ in range(count):
            cycles.append(canonical(faces[at + 1 : at + 1 + faces[at]]))
            at += 1 + faces[at]
        assert at == end
        cells.append(sorted(cycles))
        start = end
    return cells
