"""Pixels into messages, for the camera plugins: pixel formats (`to_format`), Gazebo's camera noise drawn
fast (`PixelNoise`; `add_noise` is the direct reference it is checked against), and images encoded in place
(`ImageOut`): a frame read back from OpenGL is flipped, converted and made noisy in one pass, straight into
the bytes of its message.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from plugins._render import image_msg

_LUMA = np.array([77, 150, 29], dtype=np.uint16)  # ITU-R BT.601 weights x 256 (they sum to 256)


def to_format(rgb: np.ndarray, fmt: str, out: np.ndarray | None = None) -> np.ndarray:
    """An RGB uint8 image (H x W x 3, any strides) in the pixel format `fmt` (`rgb8`, `bgr8` or `mono8`:
    ITU-R BT.601 luma), written into `out` (C-contiguous, H x W x 3 or H x W) when given."""
    if fmt == "rgb8":
        src = rgb
    elif fmt == "bgr8":
        src = rgb[..., ::-1]
    else:
        luma = ((rgb @ _LUMA) + 128) >> 8
        if out is None:
            return luma.astype(np.uint8)
        np.copyto(out, luma, casting="unsafe")
        return out
    if out is None:
        return np.ascontiguousarray(src)
    np.copyto(out, src)
    return out


class PixelNoise:
    """Gazebo's camera noise, per pixel and channel, drawn fast: the value Gazebo gives is the rendered
    intensity plus x ~ N(mean, stddev) (0..1 units, so x 255), rounded to the nearest integer and clamped to
    0..255 (its noise shader adds x to each channel and clamps; the 8-bit image rounds). For an integer
    intensity v, round(v + x) = v + round(x): the noise is an integer k = round(x), with
    P(k) = Phi((k + 1/2 - mean) / stddev) - Phi((k - 1/2 - mean) / stddev), and the result clip(v + k).

    Drawing x with `rng.normal` for each of the 1.9 M values of an 800x800 RGB frame costs ~25 ms, more
    than rendering it. Here the integers k are drawn once, at setup: a table of `TABLE` (or 16 rows, if
    more) values in which each k appears in proportion to P(k) (to 1 / table size: tails beyond ~5
    stddev are cut), shuffled with the camera's seeded generator. Each frame, every image row reads its
    noise from the table at an offset drawn anew from that generator: along a row, neighbouring values
    are different entries of the shuffled table; rows, and the same pixel in two frames, read at
    independent offsets. Adding them is done in int16 blocks of rows that stay in the cache (~0.5 ms
    for 800x800 RGB). tests/test_cameras.py checks the mean, the stddev, the distribution of k, the
    clamping and the independence between neighbouring pixels, channels and frames.
    """

    TABLE = 1 << 22
    BLOCK_ROWS = 64

    def __init__(self, stddev: float, rng: np.random.Generator, mean: float = 0.0, table: int | None = None):
        if stddev <= 0:
            raise ValueError("PixelNoise needs a positive stddev")
        self.rng = rng
        self.stddev, self.mean = float(stddev), float(mean)
        self._size = int(table or self.TABLE)
        self._table: np.ndarray | None = None
        self._rows: dict[int, np.ndarray] = {}  # row length -> sliding windows of the table
        self._tmp: np.ndarray | None = None

    def probabilities(self) -> tuple[np.ndarray, np.ndarray]:
        """(k, P(k)) of the integer noise, k clipped to -255..255 (beyond, clamping gives the same image)."""
        s, mu = self.stddev * 255.0, self.mean * 255.0
        lo, hi = math.floor(mu - 9.0 * s) - 1, math.ceil(mu + 9.0 * s) + 1
        ks = np.arange(lo, hi + 1)
        edges = [0.5 * math.erfc(-(k + 0.5 - mu) / (s * math.sqrt(2.0))) for k in range(lo, hi + 1)]
        cdf = np.array(edges)
        cdf[-1] = 1.0
        p = np.diff(cdf, prepend=0.0)
        return ks, p

    def table(self, min_size: int = 0) -> np.ndarray:
        """The shuffled table of integer noise values (made on first use, from the generator)."""
        if self._table is None or len(self._table) < min_size:
            size = max(self._size, min_size)
            ks, p = self.probabilities()
            bounds = np.rint(np.cumsum(p) * size).astype(np.int64)
            bounds[-1] = size
            counts = np.diff(bounds, prepend=0)
            values = np.clip(ks, -255, 255)
            dtype = np.int8 if values.min() >= -128 and values.max() <= 127 else np.int16
            table = np.repeat(values.astype(dtype), counts)
            self.rng.shuffle(table)
            self._table = table
            self._rows.clear()
        return self._table

    def apply(self, src: np.ndarray, out: np.ndarray) -> np.ndarray:
        """`out` = clip(`src` + noise) for uint8 images of one shape (H x W x C or H x W); `src` may have any
        strides (a view flipped upside down, channels reversed) and may be `out` itself."""
        h = src.shape[0]
        row = int(np.prod(src.shape[1:]))
        windows = self._rows.get(row)
        if windows is None:
            table = self.table(16 * row)
            windows = self._rows[row] = np.lib.stride_tricks.sliding_window_view(table, row)
        offsets = self.rng.integers(0, len(windows), size=h)
        block = min(h, self.BLOCK_ROWS)
        shape = (block, *src.shape[1:])
        if self._tmp is None or self._tmp.shape != shape:
            self._tmp = np.empty(shape, dtype=np.int16)
        tmp = self._tmp
        for r0 in range(0, h, block):
            r1 = min(h, r0 + block)
            t = tmp[: r1 - r0]
            np.add(src[r0:r1], windows[offsets[r0:r1]].reshape(t.shape), out=t, dtype=np.int16)
            np.clip(t, 0, 255, out=t)
            np.copyto(out[r0:r1], t, casting="unsafe")
        return out


def add_noise(img: np.ndarray, stddev: float, rng: np.random.Generator) -> np.ndarray:
    """Gaussian noise on uint8 intensities, `stddev` in 0..1 units, clamped to 0..255, drawn directly
    with `rng.normal` (the reference `PixelNoise` is checked against; ~25 ms for an 800x800 RGB frame)."""
    if stddev <= 0:
        return img
    noisy = img.astype(np.float32) + rng.normal(0.0, stddev * 255.0, img.shape).astype(np.float32)
    return np.clip(np.rint(noisy), 0, 255).astype(np.uint8)


class ImageOut:
    """A `sensor_msgs/Image` of one size and encoding, encoded in place (`runner.wire.cdr.Layout`): the
    frame is written into `pixels` (H x W x C, or H x W, a view of the message's CDR bytes), then
    `payload(stamp)` is those bytes with the stamp set: borrowed, valid until the next frame is written
    (`Publisher.publish_cdr` takes it as it is; the bus copies it once)."""

    def __init__(self, publisher: Any, frame_id: str, height: int, width: int, encoding: str):
        channels = {"rgb8": 3, "bgr8": 3, "mono8": 1, "32FC1": 1}[encoding]
        dtype = np.dtype("<f4") if encoding == "32FC1" else np.dtype(np.uint8)
        shape = (height, width) if channels == 1 else (height, width, channels)
        template = image_msg(0, frame_id, np.zeros(shape, dtype), encoding)
        self.layout = publisher.layout(template, ["header.stamp"])
        data = self.layout.view("data")
        self.pixels: np.ndarray = data.view(dtype).reshape(shape)

    def payload(self, now_ns: int) -> bytearray:
        return self.layout.fill(now_ns)
