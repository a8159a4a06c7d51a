"""The measuring settings (GUD-like data, spec/jog-measuring.md §8) with defaults and validation.

Each field names its SINUMERIK variable in ``gud`` so the settings screen can show it. Add a
field here and it appears in the API and on the settings screen (grouped by ``group``).
"""

from __future__ import annotations

import re
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator

SETTABLE_WO = re.compile(r"^(G500|G5[4-7]|G5(0[5-9]|[1-9][0-9]))$")


def _f(default, gud: str, label: str, group: str, unit: str = "", **constraints):
    return Field(default, description=label,
                 json_schema_extra={"gud": gud, "group": group, "unit": unit}, **constraints)


GENERAL, WORKPIECE, TOOL = "General", "Workpiece measuring", "Tool measuring"


class GudSettings(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, validate_assignment=True)

    # --- general (_JM_I, _JM_B, _CBIT) -------------------------------------------------------
    plane: Literal["G17", "G18", "G19"] = _f("G17", "_JM_I[3]", "Working plane for measuring", GENERAL)
    measuring_wo: str = _f("G500", "_JM_I[4]", "WO active during measurement (active = keep)", GENERAL)
    compensation_choice: Literal["standard", "extended"] = _f(
        "standard", "_JM_I[5]", "Compensation choice (extended adds basic frames)", GENERAL)
    probe_number: int = _f(1, "_JM_I[1]", "Workpiece probe number (_PRNUM)", GENERAL, ge=1, le=199)
    tool_probe_number: int = _f(1, "_JM_I[2]", "Tool probe number", GENERAL, ge=1, le=99)
    length_to_tip: bool = _f(False, "_CBIT[14]", "Probe length L1 to the ball end (else centre)", GENERAL)
    override_mismatch: Literal["warn", "refuse"] = _f(
        "warn", "-", "Feed override differs from calibration", GENERAL)
    inch_display: bool = _f(False, "E_MESS_IS_METRIC", "Display in inch (storage stays mm)", GENERAL)

    # --- workpiece measuring -------------------------------------------------------------------
    attempts: Literal[1, 5] = _f(1, "_JM_B[1]", "Measuring attempts", WORKPIECE)
    rapid_return: bool = _f(False, "_JM_B[2]", "Return from the measuring position in rapid", WORKPIECE)
    two_stage: bool = _f(False, "_JM_B[3]", "Fast measuring feed first, then measuring feed", WORKPIECE)
    fast_feed: float = _f(900.0, "_SPEED[3]", "Fast measuring feed", WORKPIECE, "mm/min", gt=0, le=10000)
    measuring_feed: float = _f(300.0, "E_MESS_FM", "Measuring feed", WORKPIECE, "mm/min", gt=0, le=10000)
    position_feed: float = _f(2000.0, "E_MESS_F", "Plane feed, collision monitored", WORKPIECE, "mm/min",
                              gt=0, le=50000)
    position_feed_infeed: float = _f(2000.0, "E_MESS_FZ", "Infeed feed, collision monitored", WORKPIECE,
                                     "mm/min", gt=0, le=50000)
    measuring_path: float = _f(50.0, "E_MESS_D_M", "Measuring path before/after the point", WORKPIECE, "mm",
                               gt=0, le=1000)
    spigot_safety: float = _f(5.0, "-", "Safety distance around spigots", WORKPIECE, "mm", ge=0, le=100)
    cal_ring_diameter: float = _f(0.0, "E_MESS_CAL_D", "Calibration ring diameter", WORKPIECE, "mm",
                                  ge=0, le=1000)
    cal_height: float = _f(0.0, "E_MESS_CAL_L", "Calibration height on the infeed axis (WCS)", WORKPIECE,
                           "mm", ge=-10000, le=10000)

    # --- tool measuring (_JM_B[0], E_MESS_MT_*, E_MESS_D_L/R) ---------------------------------
    tool_offset_mode: Literal["geometry", "wear"] = _f("geometry", "_JM_B[0]", "Tool offset correction", TOOL)
    mt_dl: float = _f(0.0, "E_MESS_MT_DL", "Tool probe effective diameter, length", TOOL, "mm", ge=0, le=500)
    mt_dr: float = _f(0.0, "E_MESS_MT_DR", "Tool probe effective diameter, radius", TOOL, "mm", ge=0, le=500)
    mt_dz: float = _f(2.0, "E_MESS_MT_DZ", "Probe upper edge to tool lower edge", TOOL, "mm", ge=0, le=100)
    mt_dir: Literal[-1, 1] = _f(-1, "E_MESS_MT_DIR", "Approach direction, 1st plane axis", TOOL)
    mt_d: float = _f(10.0, "E_MESS_MT_D", "Measuring path, calibration / rotating", TOOL, "mm", gt=0, le=200)
    mt_fm: float = _f(100.0, "E_MESS_MT_FM", "Measuring feed, tool probe", TOOL, "mm/min", gt=0, le=5000)
    mt_max_v: float = _f(100.0, "E_MESS_MAX_V", "Max. peripheral speed", TOOL, "m/min", gt=0, le=2000)
    mt_max_s: float = _f(1000.0, "E_MESS_MAX_S", "Max. spindle speed", TOOL, "rev/min", gt=0, le=50000)
    mt_max_f: float = _f(20.0, "E_MESS_MAX_F", "Max. feed, rotating spindle", TOOL, "mm/min", gt=0, le=5000)
    mt_min_f: float = _f(1.0, "E_MESS_MIN_F", "Min. feed, first probing", TOOL, "mm/min", gt=0, le=5000)
    mt_f_fak1: float = _f(10.0, "E_MESS_F_FAK1", "Feed factor, first probing", TOOL, ge=0, le=1000)
    mt_f_fak2: float = _f(0.0, "E_MESS_F_FAK2", "Feed factor, second probing (0 = none)", TOOL, ge=0, le=1000)
    mt_min_d: float = _f(0.01, "E_MESS_MIN_D", "Measuring accuracy, rotating spindle", TOOL, "mm",
                         gt=0, le=1)
    mt_type: Literal[0, 101, 201, 301] = _f(0, "E_MESS_MT_TYP", "Tool probe type (0 cube, 101 disc XY)", TOOL)
    mt_ax: int = _f(133, "E_MESS_MT_AX", "Permitted axis directions (digit code)", TOOL, ge=0, le=333)
    d_l: float = _f(2.0, "E_MESS_D_L", "Measuring path, length (stationary)", TOOL, "mm", gt=0, le=100)
    d_r: float = _f(1.0, "E_MESS_D_R", "Measuring path, radius (stationary)", TOOL, "mm", gt=0, le=100)

    @field_validator("measuring_wo")
    @classmethod
    def _known_wo(cls, value: str) -> str:
        value = value.strip().upper()
        if value == "ACTIVE":
            return "active"
        if not SETTABLE_WO.match(value):
            raise ValueError("must be G500, G54..G57, G505..G599 or 'active'")
        return value

    @field_validator("probe_number")
    @classmethod
    def _prnum(cls, value: int) -> int:
        if value % 100 == 0 or value // 100 not in (0, 1):
            raise ValueError("probe number 1..99, +100 for a monodirectional probe")
        return value

    @field_validator("mt_ax")
    @classmethod
    def _axis_code(cls, value: int) -> int:
        digits = f"{value:03d}"
        if any(d not in "0123" for d in digits):
            raise ValueError("each digit must be 0 (no), 1 (minus), 2 (plus) or 3 (both)")
        if digits[0] not in "13":
            raise ValueError("the tool axis (hundreds digit) must allow the minus direction")
        return value


def field_groups() -> list[tuple[str, list[tuple[str, object]]]]:
    """[(group, [(name, FieldInfo), ...])] in declaration order, for the settings screen."""
    groups: dict[str, list] = {}
    for name, info in GudSettings.model_fields.items():
        extra = info.json_schema_extra or {}
        groups.setdefault(extra.get("group", GENERAL), []).append((name, info))
    return list(groups.items())
