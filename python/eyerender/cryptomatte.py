"""Cryptomatte (Psyop's specification 1.1: Friedman and Jones, "Fully Automatic ID Mattes with Support for Motion
Blur and Transparency", SIGGRAPH 2015): ID mattes of objects, materials and assets, stable across frames and
instancing because an id is a hash of a name.

- Names: object, the prim path (an instance proxy's path for a native instance, `instancer[id]/prototype/prim`
  for a PointInstancer's); material, the bound UsdShade.Material's path (a materialBind subset's for its faces);
  asset, the nearest ancestor-or-self whose kind is a component model, else the prim's top-level ancestor.
- Ids: MurmurHash3_x86_32 (seed 0) of the UTF-8 name, as a float32 whose bits are the hash with the exponent
  clamped to [1, 254] (no denormal, inf or NaN); 0 is "no object".
- Coverage: every sample's first hit (the renderer's hitId AOV, one sample per pass) counts 1 for its id; an id's
  coverage is its count over the pixel's samples (the box filter of the beauty). The ids of a pixel are ranked by
  coverage (ties by id), and the first LEVELS written: `{name}00.R` id of rank 0, `.G` its coverage, `.B` `.A`
  rank 1, `{name}01` ranks 2 and 3, ... Counts are integers, so a farm's merged ranges give the same file.
- Header: `cryptomatte/<key>/name`, `hash` (MurmurHash3_32), `conversion` (uint32_to_float32) and `manifest`
  (JSON {name: 8 hex digits of the float's bits}), key the first 7 hex digits of the layer name's hash.

A pixel keeps at most SLOTS distinct ids; samples of more ids are counted in the pixel's total but not ranked (a
pixel of 16 distinct objects is rare; coverage of the ranked ones stays exact). Transparency (cut-outs) is not
weighed: the first opaque hit counts.
"""
import json
import struct

import numpy as np

TYPES = {"CryptoObject": 0, "CryptoMaterial": 1, "CryptoAsset": 2}  # layer name -> what its names are
LEVELS = 6  # ranks written (the specification's suggested default: 3 RGBA layers)
SLOTS = 16  # distinct ids kept per pixel
HIT_AOV = "hitId"  # the renderer's per-sample first hit: (primIndex, instance index, materialBind subset)
_MASK = 0xFFFFFFFF


def murmurhash3_32(data, seed=0):
    """MurmurHash3_x86_32 of bytes `data` (Austin Appleby's reference), an unsigned 32-bit int."""
    def rotl(x, r):
        return ((x << r) | (x >> (32 - r))) & _MASK

    def mix(k):
        return (rotl((k * 0xCC9E2D51) & _MASK, 15) * 0x1B873593) & _MASK

    h, n = seed & _MASK, len(data)
    for i in range(0, n - n % 4, 4):
        h = rotl(h ^ mix(int.from_bytes(data[i:i + 4], "little")), 13)
        h = (h * 5 + 0xE6546B64) & _MASK
    tail = data[n - n % 4:]
    if tail:
        h ^= mix(int.from_bytes(tail, "little"))
    h ^= n
    for shift, factor in ((16, 0x85EBCA6B), (13, 0xC2B2AE35)):
        h = ((h ^ (h >> shift)) * factor) & _MASK
    return h ^ (h >> 16)


def id_bits(name):
    """The float32 bits (uint32) of a name's id: its hash with the exponent clamped to [1, 254]."""
    h = murmurhash3_32(name.encode("utf-8"))
    exponent = min(max((h >> 23) & 0xFF, 1), 254)
    return (h & 0x807FFFFF) | (exponent << 23)


def id_float(name):
    """A name's id as the float32 the pixels hold."""
    return struct.unpack("<f", struct.pack("<I", id_bits(name)))[0]


def layer_key(layer):
    """The 7-character metadata key of a cryptomatte layer name."""
    return f"{murmurhash3_32(layer.encode('utf-8')):08x}"[:7]


class CoverageTable:
    """Per pixel up to SLOTS (id bits, sample count) pairs and the pixel's sample total: what a ranked pixel
    filter needs, as integers so that tables of sample ranges merge exactly."""

    def __init__(self, height, width):
        self.ids = np.zeros((height, width, SLOTS), np.uint32)
        self.counts = np.zeros((height, width, SLOTS))
        self.totals = np.zeros((height, width))

    def add(self, ids, weights, total):
        """Adds `weights` (h, w) samples of id bits `ids` (h, w; 0: none, which counts only in the total) and
        `total` (h, w) samples to the pixels' totals."""
        self.totals += total
        valid = (ids != 0) & (weights > 0)
        # Most pixels see the id they saw first again (inside an object), or their first id: slot 0 at once, the
        # rest sparsely.
        empty = valid & (self.counts[..., 0] == 0)
        self.ids[..., 0] = np.where(empty, ids, self.ids[..., 0])
        first = valid & (self.ids[..., 0] == ids)
        self.counts[..., 0] += np.where(first, weights, 0)
        ys, xs = np.nonzero(valid & ~first)
        if not len(ys):
            return
        slots, counts, new, weight = self.ids[ys, xs], self.counts[ys, xs], ids[ys, xs], weights[ys, xs]
        match = (slots == new[:, None]) & (counts > 0)
        counts += match * weight[:, None]
        free = counts == 0
        put = ~match.any(-1) & free.any(-1)  # a new id, and room for it
        rows = np.nonzero(put)[0]
        slot = free.argmax(-1)[put]
        slots[rows, slot], counts[rows, slot] = new[put], weight[put]
        self.ids[ys, xs], self.counts[ys, xs] = slots, counts

    def merge(self, other):
        """Adds another table's samples (a later sample range), slot by slot."""
        zero = np.zeros(self.totals.shape)
        for k in range(SLOTS):
            self.add(other.ids[..., k], other.counts[..., k], zero)
        self.totals += other.totals

    def encode(self, levels=LEVELS):
        """float32 (h, w, 2 levels): id and coverage of each rank, highest coverage first (ties: smaller id
        bits first); ranks past the pixel's ids are 0."""
        ids, counts = self.ids[..., :levels].copy(), self.counts[..., :levels].copy()
        # Pixels of one id (most) are ranked already; the others sorted by one int64 key per slot: most samples
        # first, then smaller id bits (counts are integers below 2^31).
        ys, xs = np.nonzero(self.counts[..., 1] > 0)
        key = ((2.0 ** 31 - 1 - self.counts[ys, xs]).astype(np.int64) << 32) | self.ids[ys, xs].astype(np.int64)
        order = np.argsort(key, axis=-1)[:, :levels]
        ids[ys, xs] = np.take_along_axis(self.ids[ys, xs], order, -1)
        counts[ys, xs] = np.take_along_axis(self.counts[ys, xs], order, -1)
        with np.errstate(invalid="ignore", divide="ignore"):
            coverage = np.where(self.totals[..., None] > 0, counts / self.totals[..., None], 0.0)
        ids = np.where(counts > 0, ids, 0)
        out = np.empty(ids.shape[:2] + (2 * levels,), np.float32)
        out[..., 0::2] = ids.astype(np.uint32).view(np.float32)
        out[..., 1::2] = coverage.astype(np.float32)
        return out


def layer_channels(name, levels=LEVELS):
    """The channel names of cryptomatte layer `name`: name00.R, name00.G, ... (levels ranks, two per channel
    pair)."""
    return tuple(f"{name}{layer:02d}.{c}" for layer in range((levels + 1) // 2) for c in "RGBA")[:2 * levels]


def header_attributes(layer, manifest):
    """The cryptomatte/<key>/... header attributes of layer `layer` (the channel prefix) with {name: id bits}."""
    key = layer_key(layer)
    return {f"cryptomatte/{key}/name": layer, f"cryptomatte/{key}/hash": "MurmurHash3_32",
            f"cryptomatte/{key}/conversion": "uint32_to_float32",
            f"cryptomatte/{key}/manifest": json.dumps({n: f"{b:08x}" for n, b in sorted(manifest.items())})}


__all__ = ["TYPES", "LEVELS", "SLOTS", "HIT_AOV", "murmurhash3_32", "id_bits", "id_float", "layer_key",
           "CoverageTable", "layer_channels", "header_attributes"]
