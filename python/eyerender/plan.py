"""The render plan from Python: what the planner (delegate/hdeye/plan/renderPlan.h) decides for each eye, the overrides
that win over it, and the JSON contract `eyerecord --plan` prints and EXRs carry in their `eyerender:plan` header
attribute (docs/render_plan.md).

Precedence, highest first: an authored schema value on the eye prim (e.g. eye:limbalArc), an explicit flag or render
setting (--no-mnee, --mnee, --mnee-all-solutions), the planner.
"""
import json

from .eyes import is_eye
from ._hdeye import PlanOverrides, PlanRules, RenderPlan

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


def plan_dict(plan):
    """The plan (a RenderPlan or its JSON string) as a Python dict."""
    return json.loads(plan if isinstance(plan, str) else plan.to_json())


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
            if key not in eye or not isinstance(eye[key], kind) or (kind == (int, float) and isinstance(eye[key], bool)):
                raise ValueError(f"plan: eye {eye.get('prim')!r}: '{key}' missing or not {kind}")
        if not all(isinstance(v, str) for v in eye["why"].values()):
            raise ValueError(f"plan: eye {eye['prim']!r}: 'why' values must be strings")
    return d


__all__ = ["PLAN_ATTRIBUTE", "CONTRACT_KEYS", "PlanOverrides", "PlanRules", "RenderPlan", "authored_eye_values",
           "make_overrides", "plan_dict", "check_contract"]
