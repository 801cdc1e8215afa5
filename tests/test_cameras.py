"""camera and depth_camera against real MuJoCo rendering (offscreen, headless EGL), the world stepped in-process."""

from __future__ import annotations

import os

# MuJoCo picks its GL backend when it is first imported: headless EGL unless the user chose one.
os.environ.setdefault("MUJOCO_GL", "egl")

import itertools
import math
import textwrap
from pathlib import Path

import numpy as np
import pytest

from plugins._pixels import PixelNoise, add_noise
from runner.errors import ScenarioError
from tests.conftest import DIFFBOT
from tests.helpers import messages, plan_of, simulate

W, H = 160, 120
FOV = 1.047
CAM_X, CAM_Z = 0.12, 0.1  # mount on base_link, in front of the chassis; base_link rests 0.05 above ground

CAM = f"pose: {{xyz: [{CAM_X}, 0, {CAM_Z}]}}, width: {W}, height: {H}, fov: {FOV}"

# A red box straight ahead and a green one to the left; a grey wall behind the robot, seen by a depth
# camera looking backwards (yaw pi) from just behind the chassis: its face is 2.0 - 0.22 = 1.78 m away.
STATIC = f"""
name: t
duration: 0.5
rate: max
world:
  models:
    - {{name: red, shape: box, size: [0.4, 0.4, 0.4], pose: {{xyz: [1.5, 0, 0.2]}}, rgba: [1, 0, 0, 1]}}
    - {{name: green, shape: box, size: [0.4, 0.4, 0.4], pose: {{xyz: [1.5, 0.6, 0.2]}}, rgba: [0, 1, 0, 1]}}
    - {{name: wall, shape: box, size: [0.1, 1.0, 0.6], pose: {{xyz: [-2.05, 0, 0.3]}}}}
robots:
  - name: r1
    description: "{DIFFBOT}"
    pose: {{xyz: [0, 0, 0.05]}}
    plugins:
      - type: camera
        params: {{{CAM}}}
      - name: bgr
        type: camera
        params: {{{CAM}, format: bgr8, image_topic: bgr/image, info_topic: bgr/info}}
      - name: mono
        type: camera
        params: {{{CAM}, format: mono8, image_topic: mono/image, info_topic: mono/info, rate: 4}}
      - name: noisy
        type: camera
        params: {{{CAM}, noise_stddev: 0.05, image_topic: noisy/image, info_topic: noisy/info}}
      - type: depth_camera
        params:
          pose: {{xyz: [-0.22, 0, {CAM_Z}], rpy: [0, 0, {math.pi}]}}
          width: {W}
          height: {H}
          rate: 5
          image_topic: rgbd/image
          info_topic: rgbd/info
      - name: short
        type: depth_camera
        params:
          pose: {{xyz: [-0.22, 0, {CAM_Z}], rpy: [0, 0, {math.pi}]}}
          width: 32
          height: 24
          far: 1.5
          publish_color: false
          points_topic: null
          depth_topic: short/depth
          depth_info_topic: null
"""
WALL_DIST = 2.0 - 0.22


@pytest.fixture(scope="module")
def static(tmp_path_factory):
    path = tmp_path_factory.mktemp("cams") / "static.yaml"
    path.write_text(STATIC)
    _world, bus = simulate(path)
    return bus


def _image(msg) -> np.ndarray:  # type: ignore[no-untyped-def]
    data = np.asarray(msg.data, dtype=np.uint8)
    if msg.encoding == "32FC1":
        return data.view("<f4").reshape(msg.height, msg.width)
    channels = msg.step // msg.width
    return data.reshape(msg.height, msg.width, channels).squeeze()


def _last(bus, suffix: str):  # type: ignore[no-untyped-def]
    return messages(bus, suffix)[-1][1]


@pytest.mark.timeout(60)
def test_camera_sees_a_red_box_ahead_the_ground_below_and_the_sky_above(static):
    msg = _last(static, "r1/camera/image_raw")
    assert (msg.width, msg.height, msg.encoding, msg.step, msg.is_bigendian) == (W, H, "rgb8", 3 * W, 0)
    assert msg.header.frame_id == "r1/base_link"
    img = _image(msg).astype(int)
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    red = (r > 120) & (g < 90) & (b < 90)
    centre = red[H // 2 - 10 : H // 2 + 10, W // 2 - 10 : W // 2 + 10]
    assert centre.mean() > 0.95
    bottom = img[-10:]  # the ground, grey: channels close together, not dark
    assert np.all(np.abs(bottom[..., 0] - bottom[..., 2]) < 30) and bottom.mean() > 60
    assert not red[-10:].any()
    assert img[:10].max() < 30  # nothing above the horizon: the background
    # +Y (left of the robot) is on the left of the image
    green = (g > 120) & (r < 90) & (b < 90)
    cols = np.nonzero(green.any(axis=0))[0]
    assert len(cols) and cols.max() < W // 2


@pytest.mark.timeout(60)
def test_bgr8_and_mono8_are_the_same_frame_in_another_format(static):
    rgb = _image(_last(static, "r1/camera/image_raw"))
    bgr_msg = _last(static, "r1/bgr/image")
    assert bgr_msg.encoding == "bgr8"
    assert np.array_equal(_image(bgr_msg), rgb[..., ::-1])
    t_mono, mono_msg = messages(static, "r1/mono/image")[-1]
    assert (mono_msg.encoding, mono_msg.step) == ("mono8", W)
    rgb_same_time = next(m for t, m in messages(static, "r1/camera/image_raw") if t == t_mono)
    luma = _image(rgb_same_time).astype(float) @ [0.299, 0.587, 0.114]
    assert np.abs(_image(mono_msg).astype(float) - luma).max() <= 1.5


@pytest.mark.timeout(60)
def test_intensity_noise_has_the_requested_stddev(static):
    clean = _image(_last(static, "r1/camera/image_raw")).astype(float)
    noisy = _image(_last(static, "r1/noisy/image")).astype(float)
    inside = (clean > 60) & (clean < 195)  # away from clamping at 0 and 255
    err = (noisy - clean)[inside]
    assert inside.sum() > 10_000
    assert abs(err.mean()) < 0.5
    assert 0.9 * 0.05 * 255 < err.std() < 1.1 * 0.05 * 255


@pytest.mark.timeout(60)
def test_noise_is_independent_between_frames_and_neighbours_in_a_real_run(static):
    """The noisy camera and the clean one see the same frames: their difference is the noise alone."""
    clean = dict(messages(static, "r1/camera/image_raw"))
    noisy = messages(static, "r1/noisy/image")
    assert len(noisy) >= 4
    fields = []
    for t, msg in noisy:
        c = _image(clean[t]).astype(float)
        fields.append((_image(msg).astype(float) - c, (c > 60) & (c < 195)))
    for (a, ia), (b, ib) in itertools.pairwise(fields):
        both = ia & ib
        assert both.sum() > 10_000
        assert abs(np.corrcoef(a[both], b[both])[0, 1]) < 0.03  # the same pixel in consecutive frames
    err, inside = fields[-1]
    right = inside[:, :-1] & inside[:, 1:]
    below = inside[:-1] & inside[1:]
    assert abs(np.corrcoef(err[:, :-1][right], err[:, 1:][right])[0, 1]) < 0.03
    assert abs(np.corrcoef(err[:-1][below], err[1:][below])[0, 1]) < 0.03
    assert not np.array_equal(fields[0][0], fields[1][0])


def _noise_frames(stddev: float, value: int, frames: int, shape=(120, 200, 3), seed: int = 7) -> np.ndarray:
    noise = PixelNoise(stddev, np.random.default_rng(seed))
    img = np.full(shape, value, dtype=np.uint8)
    out = np.empty((frames, *shape), dtype=np.uint8)
    for i in range(frames):
        noise.apply(img[::-1], out[i])  # a flipped view, as the camera hands it over
    return out


def _corr(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.corrcoef(a.reshape(-1), b.reshape(-1))[0, 1])


@pytest.mark.parametrize("stddev", [0.007, 0.05, 0.3])
def test_pixel_noise_has_gazebos_statistics(stddev: float):
    """Gazebo's camera noise: N(0, stddev) (x 255) added to each channel of each pixel, the result rounded
    and clamped. Away from 0 and 255: the integer noise k has P(k) = Phi((k+.5)/s) - Phi((k-.5)/s), mean 0,
    and it is independent between neighbouring pixels (across, down), channels and frames."""
    frames = _noise_frames(stddev, 128, 40).astype(np.int16) - 128
    n = frames.size
    s = stddev * 255
    ks = np.arange(-128, 128)  # 128 + k clamped to 0..255: k = -128 is P(x < -127.5), k = 127 P(x >= 126.5)
    cdf = np.array([0.5 * math.erfc(-(k + 0.5) / (s * math.sqrt(2))) for k in ks])
    p = np.diff(cdf, prepend=0.0)
    p[-1] += 1.0 - cdf[-1]
    want_std = math.sqrt(float((p * ks**2).sum() - (p * ks).sum() ** 2))
    assert abs(frames.mean()) < 5 * want_std / math.sqrt(n)
    assert abs(frames.std() / want_std - 1) < 0.01
    counts = np.bincount((frames.reshape(-1) + 128).astype(np.int64), minlength=256)
    expected = p * n
    big = expected > 100
    assert np.all(np.abs(counts[big] - expected[big]) < 6 * np.sqrt(expected[big]))
    assert counts[expected < 1e-3].sum() <= 2  # nothing where Gazebo's noise (almost) never goes
    for a, b in (
        (frames[:, :, :-1], frames[:, :, 1:]),  # the next pixel along a row
        (frames[:, :-1], frames[:, 1:]),  # the pixel below
        (frames[..., 0], frames[..., 1]),  # another channel of the same pixel
        (frames[:-1], frames[1:]),  # the same pixel in the next frame
        (frames[:-2], frames[2:]),
    ):
        assert abs(_corr(a, b)) < 0.005


def test_pixel_noise_clamps_as_gazebo_and_is_deterministic():
    s = 0.05 * 255
    for value, sign in ((0, 1), (255, -1)):
        out = _noise_frames(0.05, value, 10).astype(float)
        ks = np.arange(0, 128)  # E[max(0, k)] at 0 (and E[min(0, k)] at 255, by symmetry)
        cdf = np.array([0.5 * math.erfc(-(k + 0.5) / (s * math.sqrt(2))) for k in ks])
        p = np.diff(cdf, prepend=0.5)
        want = float((p * ks).sum())
        assert abs(sign * (out.mean() - value) - want) < 0.05
        assert ((out == value).mean() - cdf[0]) ** 2 < 1e-4  # clamped: k <= 0 all read 0 (or 255)
    a, b = _noise_frames(0.05, 100, 3), _noise_frames(0.05, 100, 3)
    assert np.array_equal(a, b)  # the scenario's seed decides
    assert not np.array_equal(a, _noise_frames(0.05, 100, 3, seed=8))
    assert not np.array_equal(a[0], a[1])


def test_pixel_noise_matches_drawing_each_value_with_rng_normal():
    """Against the reference (`add_noise`: rng.normal per value, rounded, clamped) on a real image's
    range of values: the same mean and stddev of the result, value by value of the input."""
    rng = np.random.default_rng(5)
    img = rng.integers(0, 256, (150, 200, 3), dtype=np.uint8)
    stddev = 0.02
    noise = PixelNoise(stddev, np.random.default_rng(6))
    fast = np.stack([noise.apply(img, np.empty_like(img)) for _ in range(12)]).astype(float)
    slow = np.stack([add_noise(img, stddev, rng) for _ in range(12)]).astype(float)
    for lo, hi in ((0, 3), (3, 252), (252, 256)):
        sel = np.broadcast_to((img >= lo) & (img < hi), fast.shape)
        d_fast, d_slow = (fast - img)[sel], (slow - img)[sel]
        assert abs(d_fast.mean() - d_slow.mean()) < 0.05
        assert abs(d_fast.std() / d_slow.std() - 1) < 0.02


@pytest.mark.timeout(60)
def test_camera_info_is_the_ideal_pinhole_of_the_fov(static):
    info = _last(static, "r1/camera/camera_info")
    f = W / (2 * math.tan(FOV / 2))
    assert (info.width, info.height, info.distortion_model) == (W, H, "plumb_bob")
    assert np.allclose(info.k, [f, 0, W / 2, 0, f, H / 2, 0, 0, 1])
    assert np.allclose(info.p, [f, 0, W / 2, 0, 0, f, H / 2, 0, 0, 0, 1, 0])
    assert np.allclose(info.r, np.eye(3).reshape(-1)) and np.allclose(info.d, 0)
    assert info.header.frame_id == "r1/base_link"
    stamps = [t for t, _ in messages(static, "r1/camera/camera_info")]
    assert stamps == [t for t, _ in messages(static, "r1/camera/image_raw")]


@pytest.mark.timeout(60)
def test_depth_reads_the_wall_distance_along_the_optical_axis_and_inf_where_nothing_is(static):
    msg = _last(static, "r1/camera/depth/image_raw")
    assert (msg.encoding, msg.step, msg.width, msg.height) == ("32FC1", 4 * W, W, H)
    depth = _image(msg)
    assert abs(depth[H // 2, W // 2] - WALL_DIST) < 0.01
    # depth along the axis, not along the ray: the same all over the flat wall
    assert np.allclose(depth[H // 2 - 20 : H // 2 + 5, W // 2 - 30 : W // 2 + 30], WALL_DIST, atol=0.01)
    assert np.isinf(depth[0, 0]) and np.isinf(depth[0, -1]) and depth[0, 0] > 0  # the sky
    assert np.all(np.isfinite(depth[-5:]))  # the ground
    # the same wall beyond `far` (1.5 m) is no return
    assert np.all(np.isinf(_image(_last(static, "r1/short/depth"))[:12]))
    assert not messages(static, "short/points") and not messages(static, "short/image_raw")


@pytest.mark.timeout(60)
def test_point_cloud_is_organized_in_the_optical_frame(static):
    depth = _image(_last(static, "r1/camera/depth/image_raw"))
    rgb = _image(_last(static, "r1/rgbd/image"))
    pc = _last(static, "r1/camera/points")
    assert (pc.height, pc.width, pc.point_step, pc.row_step) == (H, W, 16, 16 * W)
    assert [(f.name, f.offset, f.datatype, f.count) for f in pc.fields] == [
        ("x", 0, 7, 1),
        ("y", 4, 7, 1),
        ("z", 8, 7, 1),
        ("rgb", 12, 7, 1),
    ]
    assert not pc.is_dense and not pc.is_bigendian
    pts = np.asarray(pc.data, dtype=np.uint8).view("<f4").reshape(H, W, 4)
    assert len(pc.data) == W * H * 16
    c = pts[H // 2, W // 2]
    assert c[2] == depth[H // 2, W // 2]
    f = W / (2 * math.tan(FOV / 2))
    assert abs(c[0] - 0.5 * c[2] / f) < 1e-5 and abs(c[1] - 0.5 * c[2] / f) < 1e-5
    assert pts[H // 2, 10, 0] < 0 < pts[H // 2, -10, 0]  # x right
    assert pts[-1, W // 2, 1] > 0 > pts[H // 2 - 20, W // 2, 1]  # y down
    assert np.all(np.isnan(pts[0, 0, :3]))  # no return: a NaN point
    packed = pts[H // 2, W // 2, 3:].view("<u4")[0]
    assert [(packed >> 16) & 255, (packed >> 8) & 255, packed & 255] == list(rgb[H // 2, W // 2])


@pytest.mark.timeout(60)
def test_rates_are_exact_in_sim_time(static):
    for suffix, rate in (
        ("r1/camera/image_raw", 10),
        ("r1/mono/image", 4),
        ("r1/camera/depth/image_raw", 5),
        ("r1/camera/points", 5),
        ("r1/short/depth", 10),
    ):
        stamps = [t for t, _ in messages(static, suffix)]
        assert len(stamps) == int(0.5 * rate) + 1, suffix
        assert np.all(np.diff(stamps) == round(1e9 / rate)), suffix
        assert stamps[0] == 0


MOVING = f"""
name: t
duration: 1.0
rate: max
world:
  models:
    - {{name: wall, shape: box, size: [0.1, 6, 1], pose: {{xyz: [2.05, 0, 0.5]}}, rgba: [0.2, 0.3, 0.9, 1]}}
robots:
  - name: r1
    description: "{DIFFBOT}"
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive}}
      - {{type: camera, params: {{rate: 5, width: 64, height: 48, pose: {{xyz: [{CAM_X}, 0, {CAM_Z}]}}}}}}
      - type: depth_camera
        params: {{rate: 5, width: 64, height: 48, pose: {{xyz: [{CAM_X}, 0, {CAM_Z}]}}, publish_color: false}}
timeline:
  - {{t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.3}}}}}}
"""


@pytest.mark.timeout(60)
def test_images_follow_the_moving_robot(tmp_path: Path):
    path = tmp_path / "moving.yaml"
    path.write_text(MOVING)
    _, bus = simulate(path)
    images = [_image(m) for _, m in messages(bus, "r1/camera/image_raw")]
    assert len(images) == 6
    assert not np.array_equal(images[0], images[-1])
    depths = [_image(m)[24, 32] for _, m in messages(bus, "r1/camera/depth/image_raw")]
    assert abs(depths[0] - (2.0 - CAM_X)) < 0.01
    assert np.all(np.diff(depths) < 0)  # approaching the wall
    assert 0.2 < depths[0] - depths[-1] < 0.35  # about 0.3 m/s for 1 s, minus the spin-up
    _, pc = messages(bus, "r1/camera/points")[-1]
    assert pc.point_step == 12 and [f.name for f in pc.fields] == ["x", "y", "z"]


@pytest.mark.timeout(30)
@pytest.mark.parametrize(
    ("params", "where", "text"),
    [
        ("{width: 9000}", "width", "offscreen framebuffer"),
        ("{near: 5, far: 1}", "params", "far"),
        ("{depth_topic: camera/image_raw}", "params", "same topic"),
    ],
)
def test_bad_camera_params_are_scenario_errors(tmp_path: Path, params: str, where: str, text: str):
    path = tmp_path / "bad.yaml"
    path.write_text(
        textwrap.dedent(f"""\
        name: t
        robots:
          - name: r1
            description: "{DIFFBOT}"
            plugins:
              - {{type: depth_camera, params: {params}}}
        """)
    )
    with pytest.raises(ScenarioError) as e:
        plan_of(path)
    msg = str(e.value)
    assert text in msg and where in msg and ":6" in msg, msg


FULL_HD = f"""
name: t
duration: 0.1
rate: max
world:
  models:
    - {{name: red, shape: box, size: [0.4, 0.4, 0.4], pose: {{xyz: [1.5, 0, 0.2]}}, rgba: [1, 0, 0, 1]}}
robots:
  - name: r1
    description: "{DIFFBOT}"
    pose: {{xyz: [0, 0, 0.05]}}
    plugins:
      - type: camera
        params: {{pose: {{xyz: [{CAM_X}, 0, {CAM_Z}]}}, width: 1920, height: 1080, rate: 10}}
"""


@pytest.mark.timeout(60)
def test_a_full_hd_camera_grows_the_framebuffer(tmp_path: Path):
    """TurtleBot3 Waffle's R200 asks for 1920x1080, more than the default 1280x960 framebuffer."""
    path = tmp_path / "hd.yaml"
    path.write_text(FULL_HD)
    _, bus = simulate(path)
    (_, first), *_ = messages(bus, "r1/camera/image_raw")
    img = _image(first)
    assert img.shape == (1080, 1920, 3)
    red = (img[..., 0] > 120) & (img[..., 1] < 60) & (img[..., 2] < 60)
    assert red[:, 800:1120].mean() > 0.1  # the red box ahead, in the middle: the whole image is rendered


FAULTS = f"""
name: t
duration: 1.2
rate: max
seed: 2
world:
  models:
    - {{name: red, shape: box, size: [0.4, 0.4, 0.4], pose: {{xyz: [1.5, 0, 0.2]}}, rgba: [1, 0, 0, 1]}}
robots:
  - name: r1
    description: "{DIFFBOT}"
    pose: {{xyz: [0, 0, 0.05]}}
    plugins:
      - type: camera
        params: {{{CAM}, noise_stddev: 0.05}}
      - name: late
        type: camera
        params: {{{CAM}, noise_stddev: 0.05, image_topic: late/image, info_topic: late/info}}
events:
  - name: f
    when: {{at: 0.5}}
    do:
      - {{fault: {{topic: r1/camera/image_raw, freeze: true, duration: 0.3}}}}
      - {{fault: {{topic: r1/late/image, delay: 0.15, duration: 0.3}}}}
"""


@pytest.mark.timeout(60)
def test_faults_on_a_camera_keep_the_frames_they_hold(tmp_path: Path):
    """A camera writes each frame into the same buffer and publishes it borrowed: a fault that keeps a frame
    (freeze repeats the last one, delay holds them) keeps its own copy, not the buffer the next frame fills."""
    path = tmp_path / "faults.yaml"
    path.write_text(FAULTS)
    _, bus = simulate(path)
    frames = [(t, bytes(m.data)) for t, m in messages(bus, "r1/camera/image_raw")]
    before = next(data for t, data in frames if t == 500_000_000)
    during = [data for t, data in frames if 500_000_000 < t <= 800_000_000]
    assert len(during) == 3 and set(during) == {before}
    after = [data for t, data in frames if t > 800_000_000]
    assert len(after) >= 3 and before not in after and len(set(after)) == len(after)
    late = messages(bus, "r1/late/image")
    held = [(t, m) for t, m in late if m.header.stamp.sec * 10**9 + m.header.stamp.nanosec != t]
    assert len(held) == 3
    stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for _t, m in held]
    assert stamps == [600_000_000, 700_000_000, 800_000_000]
    assert len({bytes(m.data) for _t, m in late}) == len(late)  # every frame its own noise, none overwritten
