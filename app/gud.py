"""The measuring settings (GUD-like data, spec/jog-measuring.md §8) with defaults and validation.

Each field names its SINUMERIK variable in ``gud`` so the settings screen can show it. Add a
field here and it appears in the API and on the settings screen (grouped by ``group``).
"""

from __future__ import annotations

import re
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from app.access.levels import FUNCTIONS

SETTABLE_WO = re.compile(r"^(G500|G5[4-7]|G5(0[5-9]|[1-9][0-9]))$")


def _f(default, gud: str, label: str, group: str, unit: str = "", **constraints):
    return Field(default, description=label,
                 json_schema_extra={"gud": gud, "group": group, "unit": unit}, **constraints)


GENERAL, WORKPIECE, TOOL, ACCESS = "General", "Workpiece measuring", "Tool measuring", "Access levels"
TOLERANCE = "Tool offset from workpiece measuring"

# protection level a function needs (design.md §9.2, app/access/levels.py): 1..7, 0 is nobody's
AccessLevel = Literal[1, 2, 3, 4, 5, 6, 7]


def _level(function: str) -> Any:  # what pydantic's Field returns: the default, as far as mypy knows

    spec = FUNCTIONS[function]
    return _f(spec.default, "level", f"{spec.label}: level needed", ACCESS)


class GudSettings(BaseModel):
    # strict (issue 25): a JSON true is no feed of 1 mm/min, the text "12" no number; the settings
    # screen turns its typed text into numbers first (app.web.settings.parse_form)
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, validate_assignment=True, strict=True)

    # --- general (_JM_I, _JM_B, _CBIT) -------------------------------------------------------
    plane: Literal["G17", "G18", "G19"] = _f("G17", "_JM_I[3]", "Working plane for measuring", GENERAL)
    measuring_wo: str = _f("active", "_JM_I[4]", "WO active during measurement (active = keep)", GENERAL)
    compensation_choice: Literal["standard", "extended"] = _f(
        "standard", "_JM_I[5]", "Compensation choice (extended adds basic frames)", GENERAL)
    probe_number: int = _f(1, "_JM_I[1]", "Workpiece probe number", GENERAL, ge=1, le=199)
    tool_probe_number: int = _f(1, "_JM_I[2]", "Tool probe number", GENERAL, ge=1, le=99)
    length_to_tip: bool = _f(False, "_CBIT[14]", "Probe length L1 to the ball end (else centre)", GENERAL)
    override_mismatch: Literal["warn", "refuse"] = _f(
        "warn", "-", "Feed override differs from calibration", GENERAL)
    inch_display: bool = _f(False, "E_MESS_IS_METRIC", "Display in inch (storage stays mm)", GENERAL)  # = units
    calibration_invalid: Literal["warn", "refuse"] = _f(
        "warn", "-", "Measuring with an uncalibrated or invalid probe calibration", GENERAL)
    calibration_max_age_h: float = _f(0.0, "-", "Probe calibration valid for (0 = no limit)", GENERAL, "h",
                                      ge=0, le=100_000)
    repeatability_limit: float = _f(0.002, "-", "Probe repeatability limit (2σ)", GENERAL, "mm", gt=0, le=1)
    pretravel_frame: Literal["auto", "probe", "machine"] = _f(
        "auto", "-", "Probe pre-travel turns with the spindle (probe) or stays with the machine axes "
        "(auto = the ring calibration decides)", GENERAL)

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
    # KinematicsOpt-like sphere check of the kinematics measurement (design.md §10.6)
    kinematics_sphere_tolerance: float = _f(0.02, "-", "Measuring kinematics: permitted deviation of the "
                                            "calibration sphere's diameter", WORKPIECE, "mm", gt=0, le=1)
    cal_ring_diameter: float = _f(0.0, "E_MESS_CAL_D", "Calibration ring diameter", WORKPIECE, "mm",
                                  ge=0, le=1000)
    cal_chords: bool = _f(True, "-", "Ring calibration also along off-centre chords (separates eccentricity "
                          "and pre-travel)", WORKPIECE)
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

    # --- tolerance bands and the mean-value strategy (measuring-math §3.2, design.md §9.3) ----
    # the defaults of a measurement's params.tolerance (the manual's defaults, jog-measuring §3.2 table)
    tol_upper: float = _f(1.0, "_TUL", "Upper workpiece tolerance", TOLERANCE, "mm", ge=-1000, le=1000)
    tol_lower: float = _f(-1.0, "_TLL", "Lower workpiece tolerance", TOLERANCE, "mm", ge=-1000, le=1000)
    tol_zero_range: float = _f(0.001, "_TZL", "Zero offset range (no correction inside)", TOLERANCE, "mm",
                               ge=0, le=1000)
    tol_mean_range: float = _f(0.7, "_TMV", "Mean value range", TOLERANCE, "mm", ge=0, le=1000)
    tol_dim_difference: float = _f(1.2, "_TDIF", "Dimension difference check", TOLERANCE, "mm", gt=0, le=1000)
    tol_safe_area: float = _f(2.0, "_TSA", "Safe area", TOLERANCE, "mm", gt=0, le=1000)
    tol_k: int = _f(1, "_K", "Weighting factor k of the mean value", TOLERANCE, ge=1, le=1000)
    tol_evnum: int = _f(0, "_EVNUM", "Empirical/mean value memory (0 = none)", TOLERANCE, ge=0, le=999_999)
    tol_keep_mean: bool = _f(False, "_CHBIT[4]", "Carry the mean value over the parts", TOLERANCE)
    ev_add: bool = _f(False, "_CHBIT[5]", "Add the empirical value (else subtract)", TOLERANCE)
    tool_offset_geometry: bool = _f(False, "_CHBIT[6]", "Correct the geometry (else the wear)", TOLERANCE)
    repeat_on_violation: bool = _f(False, "_CBIT[0]", "Repeat the measurement after a _TSA/_TDIF violation",
                                   TOLERANCE)
    # --- access levels: the level each function needs (0 highest .. 7; app/access/levels.py) ----
    level_view: AccessLevel = _level("view")
    level_jog: AccessLevel = _level("jog")
    level_measure: AccessLevel = _level("measure")
    level_offsets: AccessLevel = _level("offsets")
    level_tools: AccessLevel = _level("tools")
    level_probe_data: AccessLevel = _level("probe_data")
    level_calibration: AccessLevel = _level("calibration")
    level_settings: AccessLevel = _level("settings")
    level_keyswitch: AccessLevel = _level("keyswitch")
    level_scenario: AccessLevel = _level("scenario")
    level_users: AccessLevel = _level("users")
    # --- trainer (issue 17 item 10): appended, the General group shows it last ----------------
    trainer_hide_part: bool = _f(False, "-", "Trainer: hide the real part in the machine view (only what "
                                 "was measured is drawn)", GENERAL)

    # --- operator screens (design.md §9.9) ------------------------------------------------------
    language: Literal["auto", "en", "de", "zh"] = _f(
        "auto", "-", "Language of the screens (auto = the browser's)", GENERAL)
    units: Literal["mm", "inch"] = _f("mm", "-", "Units of the screens (storage and API stay mm)", GENERAL)

    # --- results (design.md §10.3, docs/results.md) ---------------------------------------------
    verdict_rule: Literal["material", "scrap"] = _f(
        "material", "-", "Out of tolerance: rework when material is left over, else scrap (scrap = always scrap)",
        GENERAL)

    @model_validator(mode="before")
    @classmethod
    def _inch_display_follows_units(cls, data):
        """``inch_display`` (wave 1) is the old name of ``units == "inch"``: ``units`` rules
        (``legacy_units`` maps a change of only ``inch_display`` onto it)."""
        if isinstance(data, dict) and "units" in data:
            data = {**data, "inch_display": data["units"] == "inch"}
        return data

    @field_validator("*", mode="before")
    @classmethod
    def _no_bool_for_numbers(cls, value, info):
        """``true`` is no 1 (a strict Literal[1, 5] still takes it, since True == 1)."""
        if isinstance(value, bool) and cls.model_fields[info.field_name].annotation is not bool:
            raise ValueError("must be a number, not true/false")
        return value

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


def legacy_units(values: dict, current: dict | None = None) -> dict:
    """``values`` that set ``inch_display`` but not ``units`` set ``units`` from it (wave-1 clients)."""
    if isinstance(values, dict) and "inch_display" in values and "units" not in values:
        inch = values["inch_display"]
        if current is None or inch != current.get("inch_display"):
            return {**values, "units": "inch" if inch is True else "mm" if inch is False else inch}
    return values


def field_groups() -> list[tuple[str, list[tuple[str, object]]]]:
    """[(group, [(name, FieldInfo), ...])] in declaration order, for the settings screen."""
    groups: dict[str, list] = {}
    for name, info in GudSettings.model_fields.items():
        extra = info.json_schema_extra  # a dict here (_f), a callable is pydantic's other form
        group = extra.get("group") if isinstance(extra, dict) else None
        groups.setdefault(group if isinstance(group, str) else GENERAL, []).append((name, info))
    return list(groups.items())
