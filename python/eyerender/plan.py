"""The render plan from Python: what the planner (delegate/hdeye/plan/renderPlan.h) decides for each eye, the overrides
that win over it, and the JSON contract `eyerecord --plan` prints and EXRs carry in their `eyerender:plan` header
attribute (docs/render_plan.md).

Precedence, highest first: an authored schema value on the eye prim (e.g. eye:limbalArc), an explicit flag or render
setting (--no-mnee, --mnee, --mnee-all-solutions), the planner.
"""
import json
import math

from ._hdeye import LightStrategy, PlanOverrides, PlanRules, RenderPlan, to_string
from .eyes import is_eye

PLAN_ATTRIBUTE = "eyerender:plan"  # the EXR header attribute holding the plan's JSON
CONTRACT_KEYS = ("prim", "pixels", "mnee", "sss", "limbalArc", "why")  # every eye object has at least these


def authored_eye_values(stage, time=None):
    """{eye prim path: {"limbalArc": bool}} for EyeAPI prims whose schema values are authored (not fallbacks)."""
    from pxr import Usd

    out = {}
    for prim in stage.Traverse(Usd.TraverseInstanceProxies()):
        if not is_eye(prim):
            continue
        attr = prim.GetAttribute("eye:limbalArc")
        if attr and attr.HasAuthoredValue():
            value = attr.Get(time) if time is not None else attr.Get()
            out.setdefault(prim.GetPath().pathString, {})["limbalArc"] = bool(value)
    return out


def make_overrides(*, mnee=None, mnee_all_solutions=None, sclera_scattering=None, limbal_arc=None,
                   chamber_events=None, refine_level_ceiling=3, authored=None):
    """PlanOverrides from explicit values (None: the planner decides) and authored eye values
    ({prim path: {"limbalArc": bool}}, see authored_eye_values). chamber_events: the chamber walk's bound (events
    per path, >= 1)."""
    o = PlanOverrides()
    o.mnee, o.mnee_all_solutions = mnee, mnee_all_solutions
    o.sclera_scattering, o.limbal_arc = sclera_scattering, limbal_arc
    o.chamber_events = None if chamber_events is None else int(chamber_events)
    o.refine_level_ceiling = int(refine_level_ceiling)
    for prim, values in (authored or {}).items():
        if "limbalArc" in values:
            o.set_authored_limbal_arc(prim, bool(values["limbalArc"]))
    return o


def _num(value, digits=4):
    """A number as the plan's JSON writes it: %g with `digits` significant digits; null when not finite."""
    return "%.*g" % (digits, value) if math.isfinite(value) else "null"


def _object(pairs):
    """A JSON object from (key, already-encoded value) pairs, in order."""
    return "{" + ", ".join(f"{json.dumps(k)}: {v}" for k, v in pairs) + "}"


def _bool(value):
    return "true" if value else "false"


def _reasons(why):
    """A decision -> reason map as a JSON object, keys sorted."""
    return _object((k, json.dumps(why[k], ensure_ascii=False)) for k in sorted(why))


def _light_json(light):
    angle = "null" if light.angle_off_gaze_deg < 0 else _num(light.angle_off_gaze_deg)
    return _object((("light", json.dumps(light.light)), ("kind", json.dumps(to_string(light.kind))),
                    ("solidAngleSr", _num(light.solid_angle_sr)), ("angleOffGazeDeg", angle),
                    ("angularRadiusDeg", _num(light.angular_radius_deg)), ("reachesIris", _bool(light.reaches_iris)),
                    ("radianceContrast", _num(light.radiance_contrast)),
                    ("strategy", json.dumps(to_string(light.strategy))),
                    ("why", json.dumps(light.why, ensure_ascii=False))))


def _switch_pairs(switches):
    """An EyeSwitches record as (key, encoded value) pairs: one key per switch, the record's own names."""
    return (("mnee", _bool(switches.mnee)), ("mneeAllSolutions", _bool(switches.mnee_all_solutions)),
            ("scleraScattering", _bool(switches.sclera_scattering)), ("limbalArc", _bool(switches.limbal_arc)))


def _eye_json(eye):
    # What the renderer reads for this eye (EyeRenderOptions: the eye's switches and the rest), in the plan's words.
    mnee_lights = [json.dumps(light.light) for light in eye.lights if light.strategy == LightStrategy.MNEE]
    mnee_lights = "[" + ", ".join(mnee_lights) + "]"
    switches = eye.switches
    applied = _object((*_switch_pairs(switches), ("mneeLights", mnee_lights),
                       ("maxChamberEvents", str(eye.chamber_events)),
                       ("chamberCacheRings", str(eye.chamber_cache_rings)), ("refineLevel", str(eye.refine_level))))
    return _object((("prim", json.dumps(eye.prim)), ("geometry", json.dumps(eye.geometry)),
                    ("pixels", _num(eye.pixels, 6)), ("inView", _bool(eye.in_view)),
                    ("behindCamera", _bool(eye.behind_camera)), ("viewAngleDeg", _num(eye.view_angle_deg)),
                    ("limbusPixels", _num(eye.limbus_pixels)), ("blurPixels", _num(eye.blur_pixels)),
                    ("resolvedPixels", _num(eye.resolved_pixels, 6)), ("mnee", _bool(switches.mnee)),
                    ("mneeAllSolutions", _bool(switches.mnee_all_solutions)),
                    ("chamberEvents", str(eye.chamber_events)),
                    ("chamberCacheRings", str(eye.chamber_cache_rings)), ("sss", json.dumps(to_string(eye.sss))),
                    ("limbalArc", _bool(switches.limbal_arc)),
                    ("refineLevel", str(eye.refine_level)),
                    ("precision", '"double"'),  # the renderer's only eye arithmetic
                    ("pixelFootprintMm", _num(eye.pixel_footprint_mm)),
                    ("floatWouldSuffice", _bool(eye.float_would_suffice)), ("applied", applied),
                    ("lights", "[" + ", ".join(_light_json(light) for light in eye.lights) + "]"),
                    ("why", _reasons(eye.why))))


def _mesh_json(mesh):
    return _object((("prim", json.dumps(mesh.prim)), ("pixels", _num(mesh.pixels, 6)),
                    ("instances", str(mesh.instances)), ("sceneLevel", str(mesh.scene_level)),
                    ("refineLevel", str(mesh.refine_level)), ("why", json.dumps(mesh.why, ensure_ascii=False))))


def plan_json(plan):
    """The plan as the JSON object `eyerecord --plan` prints and EXRs carry (docs/render_plan.md). "application"
    is always "perEye": ApplyRenderPlan with the render index gives each eye its own decisions."""
    applied = _object(_switch_pairs(plan.switches))
    return _object((("version", "1"), ("camera", json.dumps(plan.camera)), ("width", str(plan.width)),
                    ("height", str(plan.height)), ("application", '"perEye"'), ("applied", applied),
                    ("why", _reasons(plan.why)), ("eyes", "[" + ", ".join(_eye_json(e) for e in plan.eyes) + "]"),
                    ("meshes", "[" + ", ".join(_mesh_json(m) for m in plan.meshes) + "]")))


def plan_dict(plan):
    """The plan (a RenderPlan or its JSON string) as a Python dict."""
    return json.loads(plan if isinstance(plan, str) else plan_json(plan))


def check_contract(plan):
    """Raises ValueError unless `plan` (dict or JSON string) holds the documented contract: an object with key
    `eyes`, a list of objects each with prim (str), pixels (number), mnee (bool), sss (str), limbalArc (bool) and
    why (an object of strings)."""
    d = plan_dict(plan) if not isinstance(plan, dict) else plan
    if not isinstance(d, dict) or not isinstance(d.get("eyes"), list):
        raise ValueError("plan: not an object with a list 'eyes'")
    types = {"prim": str, "pixels": (int, float), "mnee": bool, "sss": str, "limbalArc": bool, "why": dict}
    for eye in d["eyes"]:
        for key, kind in types.items():
            if key not in eye or not isinstance(eye[key], kind) or \
                    (kind == (int, float) and isinstance(eye[key], bool)):
                raise ValueError(f"plan: eye {eye.get('prim')!r}: '{key}' missing or not {kind}")
        if not all(isinstance(v, str) for v in eye["why"].values()):
            raise ValueError(f"plan: eye {eye['prim']!r}: 'why' values must be strings")
    return d


__all__ = ["PLAN_ATTRIBUTE", "CONTRACT_KEYS", "PlanOverrides", "PlanRules", "RenderPlan", "authored_eye_values",
           "make_overrides", "plan_json", "plan_dict", "check_contract"]
