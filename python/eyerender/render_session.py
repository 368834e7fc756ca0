"""A stage rendered through the delegate: the Hydra flow (render delegate, render index, scene store, USD scene
delegate, render pass, render buffers) built once and reused for every frame, progressive rendering with progress
callbacks and a time limit, and the outputs (EXR AOVs, PNG preview) written atomically."""
import os
import time as clock

import numpy as np
from pxr import Usd, UsdGeom

from . import cameras
from ._hdeye import (
    RenderDelegate,
    RenderIndex,
    RenderPass,
    SceneStore,
    StopFlag,
    clear_render_plan,
    write_exr,
    write_png_preview,
)
from .aovs import AOV_CHANNELS
from .camera_light import add_camera_light, follow_camera
from .cryptomatte import HIT_AOV, header_attributes
from .cryptomatte import TYPES as CRYPTO_TYPES
from .defaults import DEFAULT_SPP
from .errors import EyeRenderError
from .materials import DEFAULT_BINDING_PURPOSES
from .output_files import COLOR_CORRECTION_MODES, OUTPUT_EXTENSIONS, remove_stale_temp_files
from .plan import PlanOverrides, PlanRules, plan_json
from .shutter import ShutterOverride, resolve_shutter
from .usd_scene_delegate import UsdSceneDelegate

DEFAULT_CAMERA_ID = "/__eyerender_default_camera"
DEFAULT_CAMERA_NAME = "main_cam"  # usdrecord's default --camera
# Image size bounds: an aperture ratio beyond MAX_ASPECT (e.g. a horizontalAperture of 0.0024 mm) would ask for
# a 32 x 203877 image; MAX_PIXELS is 16k x 8k.
MAX_ASPECT = 100.0
MAX_PIXELS = 1 << 27


class RenderSession:
    """Renders one stage, frame after frame, into in-memory AOV buffers."""

    def __init__(self, stage, *, width, height=None, camera=None, aovs=("color",), purposes=("proxy",),
                 refine_level=2, cornea_model=None, time=Usd.TimeCode.Default(), settings=None, plan_overrides=None,
                 camera_light=False, strict=False, flatten_instances=False, dome_light_visible=False, shutter=None,
                 material_purposes=DEFAULT_BINDING_PURPOSES):
        """width, height: pixels (height None: from the camera's aperture ratio); camera: a prim path or a prim
        name (usdrecord's --camera), None for main_cam, else the stage's first camera, else a camera framing the
        stage; purposes: UsdGeom purposes rendered besides "default" (eyerecord's and usdrecord's default: proxy);
        material_purposes: the material binding purposes resolved, in order ("" all-purpose);
        aovs: names from AOV_CHANNELS ("color" is always rendered); settings: RenderSettings attribute
        overrides (seed, threads, max_depth, mis, mnee_all_solutions); plan_overrides: a PlanOverrides (eyerender.plan)
        turns on the render plan: before each frame it decides what the eyes need (what the overrides leave open),
        sets the settings from it, and write() stores it in the EXR header (None: no plan, the settings as given);
        camera_light: light a stage that has no light from the camera, as usdrecord does (eyerender.camera_light;
        `self.camera_light` then says whether it was added); strict: a texture that cannot be read is an
        EyeRenderError (else a warning, and its fallback renders).
        flatten_instances: every instance as its own prims, the reference for shared instancing (slow; tests).
        dome_light_visible: camera rays see dome lights (RenderSettings.dome_light_camera_visibility, usdrecord's
        --enableDomeLightVisibility; off, domes light the scene behind a black background).
        shutter: what overrides the render camera's shutter:open / shutter:close (shutter.py): a
        shutter.ShutterOverride (the render settings' switches, --shutter), or an (open, close) pair in frames
        relative to the frame ((0, 0): sharp); None: the camera's. What moves within the shutter is blurred."""
        unknown = [a for a in aovs if a not in AOV_CHANNELS]
        if unknown:
            raise EyeRenderError(f"unknown AOV '{unknown[0]}' (known: {', '.join(AOV_CHANNELS)})")
        self.aovs = ["color"] + [a for a in dict.fromkeys(aovs) if a != "color"]
        self.stage = stage
        self.delegate = RenderDelegate()
        self.index = RenderIndex(self.delegate)
        self.store = SceneStore(self.index)
        self.delegate.settings.dome_light_camera_visibility = bool(dome_light_visible)
        for name, value in (settings or {}).items():
            setattr(self.delegate.settings, name, value)
        self.scene = UsdSceneDelegate(stage, self.store, time=time, purposes=purposes, refine_level=refine_level,
                                      cornea_model=cornea_model, strict=strict,
                                      flatten_instances=flatten_instances, material_purposes=material_purposes)
        self.scene.populate()
        self.camera_id = self._choose_camera(camera, purposes, width, height)
        self.shutter_override = shutter if isinstance(shutter, ShutterOverride) or shutter is None else \
            ShutterOverride(interval=tuple(map(float, shutter)), source="--shutter").check()
        self.scene.set_shutter(self._shutter_at)
        if self.camera_id == DEFAULT_CAMERA_ID:  # a camera the scene delegate does not hold
            self.store.set_camera_params(DEFAULT_CAMERA_ID, self._default_camera_params())
        self.width = int(width)
        self.height = int(height or self._height_from_camera(width))
        check_image_size(self.width, self.height)
        self.camera_light = camera_light and not self.scene.lights
        if self.camera_light:
            add_camera_light(self.store, self._camera_to_world())
        for aov in self.buffer_aovs:
            self.store.add_render_buffer(self._buffer_id(aov), self.width, self.height, len(AOV_CHANNELS[aov]))
        self.crypto = None  # cryptomatte layers' coverage, accumulated from the hitId AOV pass by pass
        if self.crypto_layers:
            from .cryptomatte_session import CryptoCoverage

            self.store.add_render_buffer(self._buffer_id(HIT_AOV), self.width, self.height, 3)
            self.crypto = CryptoCoverage(self.scene, self.crypto_layers, self.height, self.width)
        self.render_pass = RenderPass(self.index)
        self.stop_flag = StopFlag()  # request_stop(): honoured between passes
        self.stats = None
        self.plan_overrides = plan_overrides
        self.plan_rules = PlanRules()  # the planner's thresholds (docs/render_plan.md); the sweeps move them
        self.last_plan = None  # the RenderPlan of the last frame planned (plan_overrides set)

    @property
    def crypto_layers(self):
        """The cryptomatte layers among the AOVs (CryptoObject, CryptoMaterial, CryptoAsset)."""
        return [a for a in self.aovs if a in CRYPTO_TYPES]

    @property
    def buffer_aovs(self):
        """The AOVs held in render buffers (all but the cryptomatte layers)."""
        return [a for a in self.aovs if a not in CRYPTO_TYPES]

    @staticmethod
    def _buffer_id(aov):
        return f"/__eyerender_buffers/{aov}"

    def _choose_camera(self, camera, purposes, width, height):
        known = self.scene.cameras
        if camera:
            matches = [c for c in known if c == camera or c.rsplit("/", 1)[-1] == camera]
            if not matches:
                prim = self.stage.GetPrimAtPath(camera) if camera.startswith("/") else None
                what = f"{camera} is a {prim.GetTypeName() or 'typeless prim'}, not a Camera" if prim else \
                    f"no camera '{camera}' in the stage"
                raise EyeRenderError(f"{what} (cameras: {', '.join(known) or 'none'})")
            return matches[0]
        for c in known:
            if c.rsplit("/", 1)[-1] == DEFAULT_CAMERA_NAME:
                return c
        if known:
            return known[0]
        aspect = width / height if height else 1.0
        params, world = cameras.default_camera(self.stage, self.scene.time, self.scene.purposes, aspect)
        self._default_camera_world = np.array(world, dtype=np.float64).reshape(4, 4)
        self._default_params = params
        self.store.add_camera(DEFAULT_CAMERA_ID, params, self._default_camera_world)
        return DEFAULT_CAMERA_ID

    def _shutter_at(self, time):
        """The render's shutter at frame `time` (a Usd.TimeCode): the render camera's under the override; a bad
        authored shutter is one warning (sharp)."""
        prim = self.stage.GetPrimAtPath(self.camera_id) if self.camera_id != DEFAULT_CAMERA_ID else None
        notes = []
        shutter = resolve_shutter(prim, time, self.shutter_override, notes)
        self.scene.warnings.extend(n for n in notes if n not in self.scene.warnings)
        return shutter

    def _default_camera_params(self):
        params = self._default_params
        params.shutter_open, params.shutter_close = self.scene.shutter.open, self.scene.shutter.close
        return params

    def _camera_to_world(self):
        """The render camera's camera-to-world matrix at the scene's time (4x4 float64)."""
        prim = self.stage.GetPrimAtPath(self.camera_id)
        if not prim:  # the default camera, fixed
            return self._default_camera_world
        return np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(self.scene.time),
                        dtype=np.float64).reshape(4, 4)

    def _height_from_camera(self, width):
        prim = self.stage.GetPrimAtPath(self.camera_id)
        if not prim:
            return width
        camera = prim.GetAttribute("horizontalAperture").Get(self.scene.time), \
            prim.GetAttribute("verticalAperture").Get(self.scene.time)
        aspect = self.delegate.settings.pixel_aspect_ratio  # non-square pixels: fewer rows for the same film
        return max(1, round(width * aspect * camera[1] / camera[0])) if camera[0] and camera[1] else width

    def render(self, time=None, spp=DEFAULT_SPP, time_limit=0.0, first_sample=0, progress=None, resume=False,
               on_pass=None, pass_seconds=0.25, first_pass_stride=1):
        """Renders samples [first_sample, first_sample + spp) of a frame through the delegate's progressive loop
        (RenderPass.render): the stage's edits, the render plan, the materials and lights are gathered once, then
        passes run until the samples are taken, `time_limit` seconds (0: none) are spent after the first pass, or
        request_stop() is called from any thread. progress(samples_done, spp, seconds) and on_pass(PassProgress)
        are called between passes on this thread; either returning False stops the render. pass_seconds: what a
        pass aims at (0: one sample per pass). first_pass_stride (a power of two): the first pass renders the pixels
        on a grid of that stride first, then the finer grids, with on_pass after each stage (PassProgress.stride > 1;
        progress is not called): a coarse image of the whole frame sooner. resume: keep the buffers and continue
        after the samples the last render took (a stage edit since then restarts instead). Returns a summary dict."""
        start = clock.perf_counter()
        changes = self.scene.apply_stage_changes()  # edits made to the stage since the last frame (ObjectsChanged)
        if time is not None:
            self.scene.set_time(time)
            if self.camera_light:
                follow_camera(self.store, self._camera_to_world())
        resumed = resume and self.stats is not None and time is None and not changes
        if resumed:
            first_sample = self.stats["first_sample"] + self.stats["samples_per_pixel"]
        else:
            self.clear_buffers()
            self._apply_plan()
        stats = self._run_passes(first_sample, spp, time_limit, progress, on_pass, pass_seconds, first_pass_stride)
        seconds = clock.perf_counter() - start
        render_start = seconds - stats.seconds  # sync and plan came first
        done = stats.passes + (self.stats["samples_per_pixel"] if resumed else 0)
        self.stats = {"samples_per_pixel": done, "seconds": seconds, "rays": stats.rays,
                      "rays_per_second": stats.rays / seconds if seconds > 0 else 0.0,
                      "samples_per_second": stats.samples / stats.seconds if stats.seconds > 0 else 0.0,
                      "time_to_first_pixel": render_start + stats.first_pass_seconds if stats.passes else None,
                      "time_to_preview": render_start + stats.preview_seconds if stats.preview_seconds else None,
                      "non_finite_samples": stats.non_finite_samples, "stopped": stats.stopped,
                      "catchlight_pixels": stats.catchlight_pixels,
                      "time_limit_reached": stats.time_limit_reached,
                      "first_sample": first_sample - (self.stats["samples_per_pixel"] if resumed else 0),
                      "updated": dict(self.scene.last_update),
                      "shutter": (self.scene.shutter.open, self.scene.shutter.close),
                      "stage_changes": dict(changes)}
        return self.stats

    def _apply_plan(self):
        settings = self.delegate.settings
        if self.plan_overrides is not None:
            self.last_plan = self.plan()
            self.last_plan.apply(settings, self.index)  # per eye and per light, and the global defaults
        else:
            clear_render_plan(self.index)  # no plan: no eye keeps a switch from an earlier planned frame
            self.last_plan = None

    def _run_passes(self, first_sample, spp, time_limit, progress, on_pass, pass_seconds, first_pass_stride):
        """One call of the delegate's progressive loop; the callbacks run between its passes."""
        settings = self.delegate.settings
        settings.first_sample, settings.samples_per_pixel = first_sample, int(spp)
        settings.time_limit_seconds = float(time_limit or 0.0)
        bindings = [(aov, self._buffer_id(aov)) for aov in self.buffer_aovs]
        callback = None
        if self.crypto:  # cryptomatte ranks each sample's first hit: one sample per pass, read before the next
            bindings.append((HIT_AOV, self._buffer_id(HIT_AOV)))
            pass_seconds, first_pass_stride = 0, 1
        if progress or on_pass or self.crypto:
            def callback(p):
                if self.crypto:
                    sums, counts = self.index.buffer_state(self._buffer_id(HIT_AOV))
                    self.crypto.add_pass(sums, counts, self.render_pass.prim_ids_by_index())
                    self.index.clear_buffer(self._buffer_id(HIT_AOV))
                keep_going = on_pass(p) if on_pass else None
                if progress and p.stride == 1 and progress(p.samples_done, p.samples_total, p.seconds) is False:
                    return False
                return keep_going is not False
        try:
            return self.render_pass.render(self.camera_id, bindings, callback, self.stop_flag, pass_seconds,
                                           first_pass_stride)
        except RuntimeError as e:  # bad prim data found at sync: already one line naming the prim
            raise EyeRenderError(str(e)) from None
        finally:
            settings.time_limit_seconds = 0.0
            self.stop_flag.clear()

    def clear_buffers(self):
        """Empties every AOV buffer (sums and counts) and the cryptomatte coverage; between passes the render goes
        on into empty buffers."""
        for aov in self.buffer_aovs:
            self.index.clear_buffer(self._buffer_id(aov))
        if self.crypto:
            self.index.clear_buffer(self._buffer_id(HIT_AOV))
            self.crypto.reset()

    def request_stop(self):
        """Stops the running (or the next) render after its current pass; safe from any thread."""
        self.stop_flag.request()

    def header(self):
        """The EXR header attributes of this frame's outputs: the render plan's JSON when the session plans, the time
        to first pixel, the samples per second and the catchlight's edge pixels (the writers add each cryptomatte
        layer's metadata, named as its channels are)."""
        attributes = {"eyerender:plan": plan_json(self.last_plan)} if self.last_plan is not None else {}
        if self.stats and self.stats.get("time_to_first_pixel") is not None:
            attributes["eyerender:timeToFirstPixel"] = f"{self.stats['time_to_first_pixel']:.4f} s"
            attributes["eyerender:samplesPerSecond"] = f"{self.stats['samples_per_second']:.0f}"
            attributes["eyerender:catchlightPixels"] = str(self.stats["catchlight_pixels"])
        return attributes

    def image(self, aov):
        """An AOV's pixels, float32 (height, width, components); a cryptomatte layer's ranked ids and coverage."""
        if aov in CRYPTO_TYPES:
            return self.crypto.tables[aov].encode()
        return self.index.resolved(self._buffer_id(aov))

    def buffer_state(self, aov):
        """An AOV's accumulation state (sums float64 (h, w, c), counts float64 (h, w)), as resolve_states takes."""
        return self.index.buffer_state(self._buffer_id(aov))

    def plan(self, overrides=None):
        """The render plan for the current frame (syncs; renders nothing, changes no setting). overrides: a
        PlanOverrides, default the session's (or none)."""
        overrides = overrides or self.plan_overrides or PlanOverrides()
        self.scene.apply_stage_changes()
        try:
            return self.render_pass.plan(self.camera_id, self.width, self.height, overrides, self.plan_rules)
        except RuntimeError as e:
            raise EyeRenderError(str(e)) from None

    def write(self, path, exposure=0.0, color_correction="sRGB", denoise=False):
        """Writes the AOVs to `path` by its extension: .exr (every rendered AOV, linear float, named channels) or
        .png (the colour after `exposure` stops, encoded by `color_correction`, one of COLOR_CORRECTION_MODES).
        Atomic. denoise: also the OIDN-denoised beauty (eyerender.denoise; the session must render the albedo and
        normal AOVs)."""
        write_images(path, {aov: self.image(aov) for aov in self.aovs}, exposure, attributes=self.header(),
                     color_correction=color_correction, denoise=denoise, manifests=self.manifests())

    def manifests(self):
        """{cryptomatte layer: {name: id bits}} of the last frame."""
        return dict(self.crypto.manifests) if self.crypto else {}

    def write_product(self, path, product, exposure=0.0, color_correction="sRGB", settings_path=None):
        """Writes a render product (render_products.RenderProductSpec, whose vars' AOVs this session renders) at
        `path` (write_product_images). Atomic."""
        write_product_images(path, product, {aov: self.image(aov) for aov in self.aovs}, self.header(), exposure,
                             color_correction, settings_path, self.manifests())


def _srgb_to_linear(x):
    """The inverse of the PNG writer's sRGB encoding, so that encoding its result gives x back (clamped)."""
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4).astype(np.float32)


def _write_png(path, rgb, exposure, color_correction):
    rgb = np.ascontiguousarray(rgb[:, :, :3])
    if color_correction == "disabled":  # the writer encodes sRGB: hand it values whose encoding is rgb
        rgb, exposure = np.ascontiguousarray(_srgb_to_linear(rgb * np.float32(2.0 ** exposure))), 0.0
    write_png_preview(path, rgb, exposure)


def write_images(path, images, exposure=0.0, attributes=None, color_correction="sRGB", denoise=False,
                 manifests=None):
    """Writes AOV images ({name: float32 (height, width, components)}, "color" first) to `path` as
    RenderSession.write does. Atomic. attributes: {name: string} for the EXR header (ignored for PNG).
    denoise: the beauty denoised with the albedo and normal images as guides goes beside the raw one, never over
    it: channels denoised.R/G/B in an .exr, `<name>.denoised.png` beside a .png. manifests: {cryptomatte layer:
    {name: id bits}} of the cryptomatte layers among the images, for their header metadata."""
    from .denoise import DENOISED_CHANNELS, GUIDE_AOVS, denoise_beauty, denoised_png_path

    if color_correction not in COLOR_CORRECTION_MODES:
        raise EyeRenderError(f"color correction '{color_correction}' is not one of {', '.join(COLOR_CORRECTION_MODES)}")
    ext = os.path.splitext(path)[1].lower()
    if ext not in OUTPUT_EXTENSIONS:
        raise EyeRenderError(f"output {path}: extension must be .exr or .png")
    remove_stale_temp_files(path)
    denoised = None
    if denoise:
        missing = [aov for aov in GUIDE_AOVS if aov not in images]
        if missing:
            raise EyeRenderError(f"denoise needs the {' and '.join(missing)} AOV(s)")
        denoised = denoise_beauty(images["color"], images["albedo"], images["normal"])
    try:
        if ext == ".exr":
            planes = []
            for aov, pixels in images.items():
                planes += [(name, np.ascontiguousarray(pixels[:, :, c])) for c, name in enumerate(AOV_CHANNELS[aov])]
            if denoised is not None:
                planes += [(name, np.ascontiguousarray(denoised[:, :, c])) for c, name in enumerate(DENOISED_CHANNELS)]
            header = dict(attributes or {})
            for layer, manifest in (manifests or {}).items():
                if layer in images:
                    header.update(header_attributes(layer, manifest))
            write_exr(path, planes, list(header.items()))
        else:
            _write_png(path, images["color"], exposure, color_correction)
            if denoised is not None:
                _write_png(denoised_png_path(path), denoised, exposure, color_correction)
    except RuntimeError as e:
        raise EyeRenderError(str(e)) from None


def write_product_images(path, product, images, attributes=None, exposure=0.0, color_correction="sRGB",
                         settings_path=None, manifests=None):
    """Writes a render product from AOV images ({aov: float32 (h, w, c)}): an .exr holds exactly its vars'
    channels (product_output.write_product_exr), a .png the beauty as write_images writes it. Atomic."""
    from .product_output import write_product_exr

    if path.lower().endswith(".exr"):
        write_product_exr(path, product, images, attributes, settings_path, manifests)
    else:
        write_images(path, {"color": images["color"]}, exposure, color_correction=color_correction)


def resolve_states(states):
    """Buffer states {aov: (sums float64 (h, w, c), counts float64 (h, w))}, e.g. merged from sample ranges
    rendered elsewhere, as images {aov: float32 (h, w, c)}, resolved by a render buffer itself so that they are
    exactly the pixels a session holding those states would give."""
    index = RenderIndex(RenderDelegate())
    store = SceneStore(index)
    images = {}
    for aov, (sums, counts) in states.items():
        height, width, components = sums.shape
        buffer_id = RenderSession._buffer_id(aov)
        store.add_render_buffer(buffer_id, width, height, components)
        index.add_buffer_state(buffer_id, np.ascontiguousarray(sums, dtype=np.float64),
                               np.ascontiguousarray(counts, dtype=np.float64))
        images[aov] = index.resolved(buffer_id)
    return images


def check_image_size(width, height):
    """Raises EyeRenderError unless width x height pixels is a positive size within MAX_ASPECT and MAX_PIXELS."""
    if width < 1 or height < 1:
        raise EyeRenderError(f"image size {width}x{height} must be positive")
    if max(width / height, height / width) > MAX_ASPECT or width * height > MAX_PIXELS:
        raise EyeRenderError(f"image size {width}x{height} is beyond the bounds (aspect {MAX_ASPECT:g}:1, "
                             f"{MAX_PIXELS >> 20} Mpixels): check the camera's apertures, or set --imageHeight")


def check_writable(path):
    """Fails fast, before a long render, if `path` cannot be written."""
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise EyeRenderError(f"output {path}: directory {directory} does not exist")
    if not os.access(directory, os.W_OK):
        raise EyeRenderError(f"output {path}: directory {directory} is not writable")
    if os.path.isdir(path):
        raise EyeRenderError(f"output {path} is a directory")


__all__ = ["RenderSession", "AOV_CHANNELS", "MAX_ASPECT", "MAX_PIXELS", "check_image_size", "check_writable",
           "write_images", "write_product_images", "resolve_states"]
