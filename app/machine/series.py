"""A machined-part series (design.md §9.3): the next part, cut by worn tools against the NC's data.

Each feature with ``machined_by: {"t": T}`` is cut with T's TRUE size against the tool data the
control holds at that moment (its radius + radius wear, its length + length wear), so the part
carries the cutter's error: a bore or pocket grows by 2·(R_true − R_comp), a spigot or boss
shrinks by it; a normally distributed scatter of ``scatter_sigma`` (mm, on the diameter/size)
comes on top. After the part the cutter's true radius and length get smaller by its
``wear_per_part``. The scenario's features are the programmed (nominal) part.

Nothing here knows how the HMI measures or corrects: it is the shop floor.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .scenario import Boss, Hole, Pocket, Scenario, Spigot

GROWS = {"hole": 1.0, "pocket": 1.0, "spigot": -1.0, "boss": -1.0}   # inner features grow with a bigger cutter


def compensated_radius(nc_tool: Mapping | None, fallback: float) -> float:
    """The radius the control cuts with: geometry + wear as it holds them."""
    if not nc_tool:
        return fallback
    return float(nc_tool.get("radius", fallback)) + float((nc_tool.get("wear") or {}).get("radius", 0.0))


def cut_part(base: Scenario, true_size: Mapping[int, tuple[float, float]], nc_tools: Mapping[int, Mapping],
             part_no: int, rng: np.random.Generator, scatter_sigma: float) -> Scenario:
    """Part ``part_no`` of the series: ``base``'s features cut by the cutters of ``true_size``
    ({T: (radius, length)}), the cutters themselves that size."""
    if base.workpiece is None:
        raise ValueError("the scenario has no workpiece to machine")
    features = []
    for feature in base.workpiece.features:
        if not isinstance(feature, (Hole, Pocket, Spigot, Boss)) or feature.machined_by is None:
            features.append(feature)
            continue
        made_by = feature.machined_by
        tool = base.tool(made_by.t)
        if tool is None:
            raise ValueError(f"machined_by: T{made_by.t} is not a tool of the scenario")
        error = true_size[made_by.t][0] - compensated_radius(nc_tools.get(made_by.t), tool.nominal_radius)
        grow = GROWS[feature.type] * 2.0 * error
        if isinstance(feature, (Hole, Spigot)):
            size = feature.diameter + grow + float(rng.normal(0.0, scatter_sigma)) if scatter_sigma else \
                feature.diameter + grow
            features.append(feature.model_copy(update={"diameter": size}))
        else:
            sizes = tuple(s + grow + (float(rng.normal(0.0, scatter_sigma)) if scatter_sigma else 0.0)
                          for s in feature.size)
            features.append(feature.model_copy(update={"size": sizes}))
    tools = [tool.model_copy(update=dict(zip(("radius", "length"), true_size[tool.t], strict=True)))
             if tool.t in true_size else tool for tool in base.tools]
    workpiece = base.workpiece.model_copy(update={"features": features})
    return base.model_copy(update={"workpiece": workpiece, "tools": tools, "seed": base.seed + part_no})


def new_tools(base: Scenario) -> dict[int, tuple[float, float]]:
    """The cutters' true (radius, length) before the first part."""
    return {tool.t: (tool.radius, tool.length) for tool in base.tools}


def worn(base: Scenario, true_size: Mapping[int, tuple[float, float]]) -> dict[int, tuple[float, float]]:
    """The cutters' true (radius, length) after one more part."""
    out = {}
    for t, (radius, length) in true_size.items():
        tool = base.tool(t)
        if tool is None:
            raise ValueError(f"T{t} is not a tool of the scenario")
        wear = tool.wear_per_part
        out[t] = (radius - wear.radius, length - wear.length)
    return out
