#!/usr/bin/env python3
"""Render a VTU triangle mesh written by `amc` into a PNG picture.

Elements are coloured by the red-green refinement (red triangles in a red/orange
tone, green closure triangles in a green tone, brightness varying a little with
the refinement level), or with --color-by level by a level palette. Triangles
get flat two-sided Lambert shading and thin dark edges, so the adaptive
refinement pattern is visible.

Standard library only (no numpy, no PIL).

Examples:
  render_vtu.py demo.vtu -o demo.png
  render_vtu.py demo.vtu -o zoom.png --zoom 6 --center 0.5,0.45
  render_vtu.py lshape.vtu -o corner.png --zoom 20 --center 0.5,0.5
  render_vtu.py lshape.vtu -o part.png --crop 0.4,0.4,0.6,0.6

Image coordinates for --center and --crop are normalized to [0,1] in the
un-zoomed, fitted view: u runs left to right, v runs top to bottom.
"""

import argparse
import base64
import math
import struct
import sys
import time
import xml.etree.ElementTree as ET
import zlib


class VtuError(Exception):
    pass


# --------------------------------------------------------------------------- reading

_INT_TYPES = {"Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "Int64", "UInt64"}
_FLOAT_TYPES = {"Float32", "Float64"}


_STRUCT = {"Int8": "b", "UInt8": "B", "Int16": "h", "UInt16": "H", "Int32": "i", "UInt32": "I",
           "Int64": "q", "UInt64": "Q", "Float32": "f", "Float64": "d"}


class _Binary:
    """How the file stores binary arrays: byte order, header words, compression, appended data."""

    def __init__(self, root, appended):
        self.order = ">" if root.get("byte_order") == "BigEndian" else "<"
        self.word = "Q" if root.get("header_type") == "UInt64" else "I"
        compressor = root.get("compressor") or ""
        if compressor not in ("", "vtkZLibDataCompressor"):
            raise VtuError("compressor %r is not supported (only zlib)" % compressor)
        self.zlib = bool(compressor)
        self.appended = appended  # (encoding, bytes after the '_') or None

    def decode(self, raw, what):
        """The array's bytes from its header and (compressed) data."""
        size = struct.calcsize(self.word)
        words = lambda n, at: struct.unpack_from(self.order + self.word * n, raw, at)
        try:
            if not self.zlib:
                (n,) = words(1, 0)
                return raw[size:size + n]
            blocks, _, _ = words(3, 0)
            sizes = words(blocks, 3 * size)
            at, out = (3 + blocks) * size, []
            for c in sizes:
                out.append(zlib.decompress(raw[at:at + c]))
                at += c
            return b"".join(out)
        except (struct.error, zlib.error) as e:
            raise VtuError("%s: bad binary data (%s)" % (what, e))


def _base64_run(text, nbytes):
    """Decodes base64 quantum by quantum until nbytes are out (header and data may be padded
    separately, as VTK writes them)."""
    text = "".join(text.split())
    out = bytearray()
    at = 0
    while len(out) < nbytes and at < len(text):
        out += base64.b64decode(text[at:at + 4])
        at += 4
    return bytes(out), at


def _binary_bytes(text, binary, what):
    size = struct.calcsize(binary.word)
    head, _ = _base64_run(text, 3 * size if binary.zlib else size)
    if binary.zlib:
        blocks = struct.unpack_from(binary.order + binary.word, head, 0)[0]
        head, _ = _base64_run(text, (3 + blocks) * size)
        total = (3 + blocks) * size + sum(struct.unpack_from(binary.order + binary.word * blocks, head, 3 * size))
    else:
        total = size + struct.unpack_from(binary.order + binary.word, head, 0)[0]
    raw, _ = _base64_run(text, total)
    return binary.decode(raw, what)


def _read_array(elem, what, binary):
    fmt = (elem.get("format") or "ascii").lower()
    typ = elem.get("type", "Float64")
    if typ not in _STRUCT:
        raise VtuError("%s: unsupported DataArray type %r" % (what, typ))
    if fmt == "ascii":
        words = (elem.text or "").split()
        return [int(w) for w in words] if typ in _INT_TYPES else [float(w) for w in words]
    if fmt == "binary":
        data = _binary_bytes(elem.text or "", binary, what)
    elif fmt == "appended" and binary.appended:
        encoding, appended = binary.appended
        offset = int(elem.get("offset", "0"))
        if encoding == "base64":
            data = _binary_bytes(appended[offset:].decode("ascii", "replace").split("<")[0], binary, what)
        else:
            data = binary.decode(appended[offset:], what)
    else:
        raise VtuError("%s: DataArray format=%r is not supported" % (what, fmt))
    code = _STRUCT[typ]
    count = len(data) // struct.calcsize(code)
    return list(struct.unpack(binary.order + code * count, data[:count * struct.calcsize(code)]))


def read_vtu(path):
    """Return (points, triangles, level, green); points as list of (x,y,z)."""
    with open(path, "rb") as f:
        data = f.read()
    appended = None
    start = data.find(b"<AppendedData")
    if start >= 0:
        # Raw appended data is not XML: parse the head alone and keep the data aside.
        tag_end = data.find(b">", start)
        underscore = data.find(b"_", tag_end)
        if tag_end < 0 or underscore < 0:
            raise VtuError("%s: malformed AppendedData" % path)
        encoding = b"raw" if b'encoding="raw"' in data[start:tag_end] else b"base64"
        appended = (encoding.decode(), data[underscore + 1:])
        data = data[:start] + b"</VTKFile>"
    try:
        root = ET.fromstring(data)
    except ET.ParseError as e:
        raise VtuError("%s: not a readable XML file (%s)" % (path, e))
    if root.tag != "VTKFile" or root.get("type") != "UnstructuredGrid":
        raise VtuError("%s: not a VTK UnstructuredGrid XML file" % path)
    try:
        binary = _Binary(root, appended)
    except VtuError as e:
        raise VtuError("%s: %s" % (path, e))
    piece = root.find("UnstructuredGrid/Piece")
    if piece is None:
        raise VtuError("%s: no UnstructuredGrid/Piece element" % path)
    npts = int(piece.get("NumberOfPoints", "0"))
    ncells = int(piece.get("NumberOfCells", "0"))

    pa = piece.find("Points/DataArray")
    if pa is None:
        raise VtuError("%s: no Points DataArray" % path)
    ncomp = int(pa.get("NumberOfComponents", "3"))
    coords = _read_array(pa, "Points", binary)
    if len(coords) != npts * ncomp:
        raise VtuError("%s: expected %d point coordinates, found %d" % (path, npts * ncomp, len(coords)))
    if ncomp == 3:
        points = list(zip(coords[0::3], coords[1::3], coords[2::3]))
    elif ncomp == 2:
        points = [(x, y, 0.0) for x, y in zip(coords[0::2], coords[1::2])]
    else:
        raise VtuError("%s: Points with %d components" % (path, ncomp))

    arrays = {}
    for da in piece.findall("Cells/DataArray"):
        arrays[da.get("Name")] = da
    for name in ("connectivity", "offsets"):
        if name not in arrays:
            raise VtuError("%s: Cells has no %r DataArray" % (path, name))
    conn = _read_array(arrays["connectivity"], "connectivity", binary)
    offs = _read_array(arrays["offsets"], "offsets", binary)
    types = _read_array(arrays["types"], "types", binary) if "types" in arrays else [5] * len(offs)
    if len(offs) != ncells or len(types) != ncells:
        raise VtuError("%s: Cells arrays do not match NumberOfCells=%d" % (path, ncells))

    cell_data = {}
    cd = piece.find("CellData")
    if cd is not None:
        for da in cd.findall("DataArray"):
            vals = _read_array(da, da.get("Name", "?"), binary)
            if len(vals) == ncells:
                cell_data[da.get("Name")] = vals
    level_c = cell_data.get("level", [0] * ncells)
    green_c = cell_data.get("green", [0] * ncells)

    tris, level, green = [], [], []
    if all(t == 5 for t in types) and len(conn) == 3 * ncells:
        tris = list(zip(conn[0::3], conn[1::3], conn[2::3]))
        level, green = list(level_c), list(green_c)
    else:
        # Generic cells: fan-triangulate polygons (triangle 5, polygon 7, quad 9),
        # skip everything else.
        start = 0
        for c in range(ncells):
            end = offs[c]
            if types[c] in (5, 7, 9) and end - start >= 3:
                a = conn[start]
                for k in range(start + 1, end - 1):
                    tris.append((a, conn[k], conn[k + 1]))
                    level.append(level_c[c])
                    green.append(green_c[c])
            start = end
    for t in tris:
        if max(t) >= npts or min(t) < 0:
            raise VtuError("%s: connectivity refers to a point out of range" % path)
    return points, tris, level, green


# --------------------------------------------------------------------------- colours

RED = (222, 72, 48)
GREEN = (70, 178, 76)
# A perceptually ordered palette (viridis-like) sampled at 9 stops.
LEVEL_STOPS = [
    (68, 1, 84), (71, 44, 122), (59, 81, 139), (44, 113, 142), (33, 144, 141),
    (39, 173, 129), (92, 200, 99), (170, 220, 50), (253, 231, 37),
]


def _palette(t):
    t = min(max(t, 0.0), 1.0) * (len(LEVEL_STOPS) - 1)
    i = min(int(t), len(LEVEL_STOPS) - 2)
    f = t - i
    a, b = LEVEL_STOPS[i], LEVEL_STOPS[i + 1]
    return tuple(a[k] + (b[k] - a[k]) * f for k in range(3))


def base_colors(level, green, color_by):
    lmin = min(level) if level else 0
    lmax = max(level) if level else 0
    span = max(lmax - lmin, 1)
    cache = {}
    out = []
    for lv, g in zip(level, green):
        key = (lv, 1 if g else 0)
        c = cache.get(key)
        if c is None:
            t = (lv - lmin) / span
            if color_by == "level":
                c = _palette(t)
                if g:  # green closure triangles: a little lighter
                    c = tuple(x + (255 - x) * 0.35 for x in c)
            else:
                base = GREEN if g else RED
                # Coarse levels darker, fine levels lighter: a gentle ramp.
                f = 0.68 + 0.32 * t
                c = tuple(x * f for x in base)
                if t > 0.5:
                    c = tuple(x + (255 - x) * (t - 0.5) * 0.45 for x in c)
            cache[key] = c
        out.append(c)
    return out


# --------------------------------------------------------------------------- PNG

def write_png(path, width, height, rows):
    """rows: list of bytes-like objects of length 3*width (RGB8)."""
    raw = bytearray()
    for r in rows:
        raw.append(0)
        raw += r

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data +
                struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


# --------------------------------------------------------------------------- rendering

def _parse_pair(s, name):
    try:
        a, b = (float(x) for x in s.split(","))
    except ValueError:
        raise SystemExit("--%s expects two numbers u,v" % name)
    return a, b


def render(points, tris, level, green, args):
    # View frame. Eye direction e points from the object to the viewer.
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    zs = [p[2] for p in points]
    ext = max(max(xs) - min(xs), max(ys) - min(ys), max(zs) - min(zs), 1e-300)
    flat = (max(zs) - min(zs)) <= 1e-9 * ext
    az, el = args.azimuth, args.elevation
    if args.top or (flat and az is None and el is None):
        az, el = -90.0, 90.0
    az = 30.0 if az is None else az
    el = 20.0 if el is None else el
    a, b = math.radians(az), math.radians(el)
    e = (math.cos(b) * math.cos(a), math.cos(b) * math.sin(a), math.sin(b))
    r = (-math.sin(a), math.cos(a), 0.0)
    u = (e[1] * r[2] - e[2] * r[1], e[2] * r[0] - e[0] * r[2], e[0] * r[1] - e[1] * r[0])

    # Projected coordinates of the whole mesh, for the fitted view.
    sx = [p[0] * r[0] + p[1] * r[1] + p[2] * r[2] for p in points]
    sy = [p[0] * u[0] + p[1] * u[1] + p[2] * u[2] for p in points]
    sz = [p[0] * e[0] + p[1] * e[1] + p[2] * e[2] for p in points]
    used = set()
    for t in tris:
        used.update(t)
    if not used:
        raise VtuError("the mesh has no triangles")
    xmin = min(sx[i] for i in used)
    xmax = max(sx[i] for i in used)
    ymin = min(sy[i] for i in used)
    ymax = max(sy[i] for i in used)
    side = max(xmax - xmin, ymax - ymin, 1e-300) * (1.0 + 2 * args.margin)
    cx, cy = 0.5 * (xmin + xmax), 0.5 * (ymax + ymin)
    # Fitted view: normalized (un, vn) in [0,1]^2, vn downwards.
    #   un = (x - cx)/side + 0.5 ; vn = (cy - y)/side + 0.5

    # Window in normalized coordinates.
    w0, h0, w1, h1 = 0.0, 0.0, 1.0, 1.0
    if args.crop:
        try:
            w0, h0, w1, h1 = (float(v) for v in args.crop.split(","))
        except ValueError:
            raise SystemExit("--crop expects x0,y0,x1,y1")
        if not (w1 > w0 and h1 > h0):
            raise SystemExit("--crop needs x1 > x0 and y1 > y0")
    if args.zoom and args.zoom != 1.0 or args.center:
        zc = args.zoom or 1.0
        cu, cv = _parse_pair(args.center, "center") if args.center else (
            0.5 * (w0 + w1), 0.5 * (h0 + h1))
        hw, hh = 0.5 * (w1 - w0) / zc, 0.5 * (h1 - h0) / zc
        w0, w1, h0, h1 = cu - hw, cu + hw, cv - hh, cv + hh
    ww, wh = w1 - w0, h1 - h0
    if ww >= wh:
        W = args.size
        H = max(1, int(round(args.size * wh / ww)))
    else:
        H = args.size
        W = max(1, int(round(args.size * ww / wh)))
    scale = W / (ww * side)  # pixels per model unit
    # pixel x = ((x - cx)/side + 0.5 - w0) * W/ww
    ox = (0.5 - w0) * W / ww - cx * scale
    oy = (0.5 - h0) * H / wh + cy * scale
    px = [x * scale + ox for x in sx]
    py = [oy - y * scale for y in sy]

    # Light: a headlight from upper-left-front (view space), two-sided Lambert.
    lx, ly, lz = -0.35, 0.45, 1.0
    ln = math.sqrt(lx * lx + ly * ly + lz * lz)
    L = tuple((lx * r[k] + ly * u[k] + lz * e[k]) / ln for k in range(3))
    ambient, diffuse = 0.35, 0.65

    cols = base_colors(level, green, args.color_by)
    ntri = len(tris)
    shaded = [None] * ntri
    edge_k = [0.0] * ntri

    N = W * H
    zbuf = [-1e300] * N
    tid = [-1] * N
    dist = [0.0] * N
    ceil, floor = math.ceil, math.floor
    edge_w = args.edge_width
    edge_s = args.edge_strength
    drawn = 0

    for t in range(ntri):
        i0, i1, i2 = tris[t]
        x0, y0 = px[i0], py[i0]
        x1, y1 = px[i1], py[i1]
        x2, y2 = px[i2], py[i2]
        # Screen-space bounding box of pixel centres (pixel c covers [c, c+1)).
        mnx = x0 if x0 < x1 else x1
        if x2 < mnx:
            mnx = x2
        mxx = x0 if x0 > x1 else x1
        if x2 > mxx:
            mxx = x2
        mny = y0 if y0 < y1 else y1
        if y2 < mny:
            mny = y2
        mxy = y0 if y0 > y1 else y1
        if y2 > mxy:
            mxy = y2
        ix0 = ceil(mnx - 0.5)
        ix1 = floor(mxx - 0.5)
        iy0 = ceil(mny - 0.5)
        iy1 = floor(mxy - 0.5)
        if ix0 < 0:
            ix0 = 0
        if iy0 < 0:
            iy0 = 0
        if ix1 >= W:
            ix1 = W - 1
        if iy1 >= H:
            iy1 = H - 1
        if ix0 > ix1 or iy0 > iy1:
            continue
        area2 = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if area2 == 0.0:
            continue
        z0, z1, z2 = sz[i0], sz[i1], sz[i2]
        if area2 < 0.0:
            x1, y1, z1, x2, y2, z2 = x2, y2, z2, x1, y1, z1
            area2 = -area2
        # Edge functions E(a,b,p) = A*x + B*y + C, >= 0 inside; E_i is opposite v_i.
        A0 = y1 - y2; B0 = x2 - x1; C0 = x1 * y2 - x2 * y1
        A1 = y2 - y0; B1 = x0 - x2; C1 = x2 * y0 - x0 * y2
        A2 = y0 - y1; B2 = x1 - x0; C2 = x0 * y1 - x1 * y0
        inv = 1.0 / area2
        # Depth plane z = dzx*x + dzy*y + dzc (barycentric interpolation).
        dzx = (A0 * z0 + A1 * z1 + A2 * z2) * inv
        dzy = (B0 * z0 + B1 * z1 + B2 * z2) * inv
        dzc = (C0 * z0 + C1 * z1 + C2 * z2) * inv
        # Normalize edge functions to signed distances in pixels.
        l0 = math.sqrt(A0 * A0 + B0 * B0)
        l1 = math.sqrt(A1 * A1 + B1 * B1)
        l2 = math.sqrt(A2 * A2 + B2 * B2)
        A0 /= l0; B0 /= l0; C0 /= l0
        A1 /= l1; B1 /= l1; C1 /= l1
        A2 /= l2; B2 /= l2; C2 /= l2
        hit = False
        for iy in range(iy0, iy1 + 1):
            yc = iy + 0.5
            k0 = B0 * yc + C0
            k1 = B1 * yc + C1
            k2 = B2 * yc + C2
            lo = mnx
            hi = mxx
            # Span of x where all three edge functions are >= 0.
            if A0 > 0.0:
                v = -k0 / A0
                if v > lo: lo = v
            elif A0 < 0.0:
                v = -k0 / A0
                if v < hi: hi = v
            elif k0 < 0.0:
                continue
            if A1 > 0.0:
                v = -k1 / A1
                if v > lo: lo = v
            elif A1 < 0.0:
                v = -k1 / A1
                if v < hi: hi = v
            elif k1 < 0.0:
                continue
            if A2 > 0.0:
                v = -k2 / A2
                if v > lo: lo = v
            elif A2 < 0.0:
                v = -k2 / A2
                if v < hi: hi = v
            elif k2 < 0.0:
                continue
            jx0 = ceil(lo - 0.5)
            jx1 = floor(hi - 0.5)
            if jx0 < ix0:
                jx0 = ix0
            if jx1 > ix1:
                jx1 = ix1
            if jx0 > jx1:
                continue
            zr = dzy * yc + dzc
            row = iy * W
            for ix in range(jx0, jx1 + 1):
                xc = ix + 0.5
                z = dzx * xc + zr
                idx = row + ix
                if z > zbuf[idx]:
                    zbuf[idx] = z
                    tid[idx] = t
                    d = A0 * xc + k0
                    d1 = A1 * xc + k1
                    if d1 < d:
                        d = d1
                    d1 = A2 * xc + k2
                    if d1 < d:
                        d = d1
                    dist[idx] = d
                    hit = True
        if hit:
            drawn += 1
            # Flat shading from the world-space face normal (two-sided).
            pa, pb, pc = points[i0], points[i1], points[i2]
            ax, ay, az_ = pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]
            bx, by, bz = pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]
            nx, ny, nz = ay * bz - az_ * by, az_ * bx - ax * bz, ax * by - ay * bx
            nl = math.sqrt(nx * nx + ny * ny + nz * nz)
            s = abs(nx * L[0] + ny * L[1] + nz * L[2]) / nl if nl > 0.0 else 1.0
            f = ambient + diffuse * s
            c = cols[t]
            shaded[t] = (c[0] * f, c[1] * f, c[2] * f)
            # Fade edges on triangles only a few pixels across, so dense regions
            # read as darker rather than as solid black.
            inr = area2 / (l0 + l1 + l2)  # inradius in pixels
            k = (inr - 0.8) / 3.0
            edge_k[t] = edge_s * (0.15 if k < 0.15 else 1.0 if k > 1.0 else k)

    # Compose: background white, edge darkening from the distance to the nearest edge.
    bg = bytes((255, 255, 255))
    rows = []
    e_lo = edge_w + 0.5  # full darkening below edge_w - 0.5, none above edge_w + 0.5
    for iy in range(H):
        out = bytearray(bg * W)
        base = iy * W
        o = 0
        for ix in range(W):
            t = tid[base + ix]
            if t >= 0:
                c = shaded[t]
                a = e_lo - dist[base + ix]
                if a > 0.0:
                    if a > 1.0:
                        a = 1.0
                    f = 1.0 - edge_k[t] * a
                    out[o] = int(c[0] * f)
                    out[o + 1] = int(c[1] * f)
                    out[o + 2] = int(c[2] * f)
                else:
                    out[o] = int(c[0])
                    out[o + 1] = int(c[1])
                    out[o + 2] = int(c[2])
            o += 3
        rows.append(out)
    return W, H, rows, drawn, (az, el)


def main(argv=None):
    ap = argparse.ArgumentParser(
        description="Render an amc VTU triangle mesh (red/green refinement) to PNG.",
        epilog="--center and --crop use normalized [0,1] coordinates of the fitted, "
               "un-zoomed view (u to the right, v downwards).")
    ap.add_argument("input", help="VTU file (ascii UnstructuredGrid, triangles)")
    ap.add_argument("-o", "--output", help="PNG file (default: input with .png)")
    ap.add_argument("--size", type=int, default=1000, help="longer image side in pixels (1000)")
    ap.add_argument("--azimuth", type=float, default=None, help="view azimuth in degrees (30)")
    ap.add_argument("--elevation", type=float, default=None, help="view elevation in degrees (20)")
    ap.add_argument("--top", action="store_true",
                    help="view from +z (automatic for flat meshes in z=0 unless an angle is given)")
    ap.add_argument("--color-by", choices=("scheme", "level"), default="scheme",
                    help="scheme: red/green triangles, shade by level; level: level palette")
    ap.add_argument("--zoom", type=float, default=None, help="magnification around --center")
    ap.add_argument("--center", default=None, help="u,v zoom centre (default: window centre)")
    ap.add_argument("--crop", default=None, help="x0,y0,x1,y1 window of the fitted view")
    ap.add_argument("--edge-width", type=float, default=0.6,
                    help="half-width in pixels of the dark triangle edges (0.6)")
    ap.add_argument("--edge-strength", type=float, default=0.7,
                    help="edge darkening 0..1 (0.7; 0 disables edges)")
    ap.add_argument("--margin", type=float, default=0.02, help="border around the fitted view")
    args = ap.parse_args(argv)
    if args.size < 1:
        ap.error("--size must be positive")
    if args.zoom is not None and args.zoom <= 0:
        ap.error("--zoom must be positive")
    out = args.output or (args.input[:-4] if args.input.endswith(".vtu") else args.input) + ".png"

    t0 = time.time()
    try:
        points, tris, level, green = read_vtu(args.input)
    except (VtuError, OSError) as e:
        print("render_vtu: %s" % e, file=sys.stderr)
        return 1
    t1 = time.time()
    try:
        W, H, rows, drawn, (az, el) = render(points, tris, level, green, args)
    except VtuError as e:
        print("render_vtu: %s" % e, file=sys.stderr)
        return 1
    t2 = time.time()
    write_png(out, W, H, rows)
    t3 = time.time()
    ng = sum(1 for g in green if g)
    print("%s: %d points, %d triangles (%d green), levels %d..%d; view az %g el %g; "
          "%d triangles rasterized; %dx%d px -> %s; read %.1fs render %.1fs png %.1fs"
          % (args.input, len(points), len(tris), ng, min(level) if level else 0,
             max(level) if level else 0, az, el, drawn, W, H, out, t1 - t0, t2 - t1, t3 - t2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
