"""Motion samples through the bindings: the scene store's set_*_samples calls, the camera's shutter and the render's
time strata reach the C++ delegate, which blurs what moves and leaves a static scene untouched."""
import numpy as np
import pytest

hdeye = pytest.importorskip("eyerender._hdeye")

QUAD_COUNTS = np.array([4], np.int32)
QUAD_INDICES = np.array([0, 1, 2, 3], np.int32)


def _quad(half, dx=0.0):
    return np.array([[-half + dx, -half, 0], [half + dx, -half, 0], [half + dx, half, 0], [-half + dx, half, 0]],
                    np.float32)


def _translate(x, y, z):
    m = np.eye(4)
    m[3, :3] = (x, y, z)  # USD's layout: row vectors, translation in the last row
    return m


def _render(setup, shutter, strata=0, spp=16):
    delegate = hdeye.RenderDelegate()
    index = hdeye.RenderIndex(delegate)
    store = hdeye.SceneStore(index)
    setup(store)
    camera = hdeye.CameraParams()
    camera.orthographic = True
    camera.horizontal_aperture = 4
    camera.vertical_aperture = 1
    camera.shutter_open, camera.shutter_close = shutter
    store.add_camera("/cam", camera, _translate(0, 0, 5))
    store.add_render_buffer("/color", 32, 8, 4)
    delegate.settings.samples_per_pixel = spp
    delegate.settings.time_strata = strata
    stats = hdeye.RenderPass(index).execute("/cam", [("color", "/color")])
    assert stats.non_finite_samples == 0
    return index.resolved("/color")[..., 3], delegate.warnings()  # alpha: where the camera rays met geometry


def _moving_square(store):
    store.add_mesh("/square", QUAD_COUNTS, QUAD_INDICES, _quad(0.25), np.eye(4))
    store.set_transform_samples("/square", [-0.5, 0.5], [_translate(-1, 0, 0), _translate(1, 0, 0)])


def test_a_square_moving_over_an_open_shutter_covers_its_whole_sweep_a_quarter_of_the_time():
    sharp, _ = _render(_moving_square, (0, 0))
    blurred, _ = _render(_moving_square, (-0.5, 0.5), strata=16)
    # Columns are 1/8 unit wide; the square spans 0.5 units and sweeps 2: covered 1/4 of the time inside the band.
    band = blurred[2:6, 10:22].mean()
    assert abs(band - 0.25) < 0.03, band
    assert sharp[:, :12].max() == 0 and sharp[:, 20:].max() == 0  # sharp: only the centre
    assert blurred[:, :5].max() == 0 and blurred[:, 27:].max() == 0  # nothing past the sweep


def test_points_and_instance_transform_samples_take_lists_of_numpy_arrays():
    def deforming(store):
        store.add_mesh("/square", QUAD_COUNTS, QUAD_INDICES, _quad(0.25), np.eye(4))
        store.set_points_samples("/square", [-0.5, 0.5], [_quad(0.25, -1), _quad(0.25, 1)])

    blurred, _ = _render(deforming, (-0.5, 0.5), strata=16)
    assert abs(blurred[2:6, 10:22].mean() - 0.25) < 0.03

    def instanced(store):
        store.add_instancer("/inst", np.stack([np.eye(4)]))
        store.set_instance_transform_samples("/inst", [-0.5, 0.5], [np.stack([_translate(-1, 0, 0)]),
                                                                   np.stack([_translate(1, 0, 0)])])
        store.add_mesh("/square", QUAD_COUNTS, QUAD_INDICES, _quad(0.25), np.eye(4), instancer_id="/inst")

    blurred, _ = _render(instanced, (-0.5, 0.5), strata=16)
    assert abs(blurred[2:6, 10:22].mean() - 0.25) < 0.03


def test_a_static_scene_renders_the_same_with_and_without_a_shutter():
    def still(store):
        store.add_mesh("/square", QUAD_COUNTS, QUAD_INDICES, _quad(0.25), np.eye(4))

    closed, _ = _render(still, (0, 0))
    opened, _ = _render(still, (-0.25, 0.25))
    assert np.array_equal(closed, opened)


def test_bad_motion_samples_are_skipped_with_a_warning_and_bad_calls_raise():
    def mirrored(store):
        store.add_mesh("/square", QUAD_COUNTS, QUAD_INDICES, _quad(0.25), np.eye(4))
        flip = np.diag([-1.0, 1, 1, 1])
        store.set_transform_samples("/square", [-0.5, 0.0, 0.5], [np.eye(4), flip, _translate(0.5, 0, 0)])

    _, warnings = _render(mirrored, (-0.5, 0.5))
    assert any("/square" in w and "mirrors" in w for w in warnings), warnings
    store = hdeye.SceneStore(hdeye.RenderIndex(hdeye.RenderDelegate()))
    store.add_mesh("/m", QUAD_COUNTS, QUAD_INDICES, _quad(0.25), np.eye(4))
    with pytest.raises(ValueError, match="sample times"):
        store.set_transform_samples("/m", [0.0, 1.0], [np.eye(4)])
    with pytest.raises(ValueError, match="differ in count"):
        store.set_points_samples("/m", [0.0, 1.0], [_quad(0.25), _quad(0.25)[:3]])
