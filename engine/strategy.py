"""Result checking and compensation strategy: tolerance bands, empirical and mean values.

Spec: measuring-math §3 (manual §1.9–§1.11, §2.3.11, §2.3.14–§2.3.16, §9.2; seeds 000, 004),
measuring-math §1.4 (_NMSP), measuring-math §4; turning.md §0.11; design.md §9.3 (names of the tolerance keys and the
decision slugs). Pure: plain numbers in, frozen value objects out; the caller reads and writes
the _EV[]/_MV[] memories and the tool data.

Flows (measuring-math §3.5, checked in the order given):

- ``decide_tool_offset``      workpiece measuring with automatic tool offset (CYCLE974/977/978/979/994)
- ``decide_tool_measurement`` tool measuring (CYCLE971/972/982)
- ``decide_calibration``      workpiece / tool probe calibration (CYCLE976/973, CYCLE971/972/982)
- ``decide_zero_offset``      workpiece measuring with ZO correction (only _TSA)
- ``repeat_measurement``      the repeat rule after a _TSA/_TDIF violation (_CBIT[0], _CBIT[1])

Threshold comparisons [I] (measuring-math §17 Q10): the manual's flowchart uses strict ">" for
the workpiece flow, the tool-measuring examples "≥ _TDIF" and "< _TZL". Every comparison carries
a guard of ``EPS`` = 1e-9 (units of the quantity: mm, inch or deg), so that a deviation equal
to a limit in its decimal notation (132.03 − 132 against 0.03, which is 3.0000000000001137e-2 in
binary) counts as *equal*: "exceeds" means "exceeds by more than 1e-9", "≥" means "reaches it
to within 1e-9". Below the measuring resolution of any machine, so it only pins equality.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields, replace
from typing import Any, cast

from engine import alarms, checks
from engine.alarms import AlarmDef
from engine.types import MeasuringError

__all__ = [
    "DECISIONS", "EPS", "CalibrationDecision", "Decision", "Memories", "RepeatAction", "Tolerance",
    "ToolMeasureDecision", "ZeroOffsetDecision", "average", "decide_calibration",
    "decide_tool_measurement", "decide_tool_offset", "decide_zero_offset", "decode_evnum",
    "mean_value", "repeat_measurement",
]

EPS = 1e-9

# design.md §9.3 result key ``decision``
DECISIONS = ("none", "mean", "full", "oversize", "undersize", "dimension_difference", "safe_area")
_CORRECTING = frozenset({"mean", "full", "oversize", "undersize"})

MAX_REPETITIONS = 4           # manual §9.2 _CBIT[0]: "repeat, at most 4 times"
_EVNUM_MAX = 9999_9999        # manual §2.3.14: MV in the upper 4 digits, EV in the lower 4


# --- small helpers ---------------------------------------------------------------------------


def average(values: object) -> float:
    """Arithmetic mean of the _NMSP measurements at the same point: D = (S1 + … + Sn)/n.

    manual §2.3.15, measuring-math §1.4 (seed 000 R27). A single number is returned as it is.
    """
    if checks.is_number(values):
        return checks.real("actual", values)
    arr = [checks.real("actual", v) for v in cast(Iterable[object], values)]   # not a number: a sequence
    if not arr:
        raise ValueError("actual: at least one measurement is needed (_NMSP >= 1)")
    return float(sum(arr) / len(arr))


def _check_weighting(k: object) -> int:
    """_K: integer >= 1 (manual appendix "_K 整型 ≥1"); 0 (or below) is alarm 61318.

    Why a MeasuringError and not a ValueError: the manual makes _K = 0 a cycle alarm of its
    own (61318 "Check weighting factor _K", NC-Reset class, cycles 974/977/978/979/994/998),
    raised by the cycle when it starts, with an operator remedy in the catalogue; _K is an INT
    the NC happily holds, so it is a legal input the cycle refuses, like any other cycle alarm.
    A non-integer _K cannot be held by the INT parameter at all, that is a ValueError.
    """
    value = checks.integer("k", k)
    if value < 1:
        raise MeasuringError(alarms.WEIGHTING_FACTOR, f"k (_K) = {value}: the weighting factor must be >= 1")
    return value


# --- measuring-math §3.3 _EVNUM -----------------------------------------------------------------------------

@dataclass(frozen=True)
class Memories:
    """The 1-based EV and MV memory numbers an _EVNUM selects (None = no memory).

    Memory number n is the array element ``_EV[n−1]`` / ``_MV[n−1]``; design.md §9.3 addresses
    the memories by n (``/api/memories/ev/10`` is ``_EV[9]``).
    """

    ev: int | None
    mv: int | None

    @property
    def ev_index(self) -> int | None:
        """Index into _EV[] (0-based)."""
        return None if self.ev is None else self.ev - 1

    @property
    def mv_index(self) -> int | None:
        """Index into _MV[] (0-based)."""
        return None if self.mv is None else self.mv - 1


def decode_evnum(evnum: object, sizes: tuple[int, int] | None = (20, 20)) -> Memories:
    """_EVNUM → (EV memory number, MV memory number), manual §2.3.14, measuring-math §3.3.

    0: neither; 1…9999: EV = MV = _EVNUM; > 9999: the digits above the lower four are the MV
    memory, the lower four the EV memory (_EVNUM = MV·10000 + EV); lower four = 0 → no EV.
    Examples (manual): 11 → EV 11 (_EV[10]), MV 11 (_MV[10]); 90012 → EV 12 (_EV[11]),
    MV 9 (_MV[8]). ``sizes`` = _EVMVNUM[0], [1] (array sizes, default 20 each); a memory beyond
    them is a ValueError (the manual lists no alarm for it); None = unchecked.
    """
    n = checks.integer("evnum", evnum)
    if n < 0 or n > _EVNUM_MAX:
        raise ValueError(f"evnum must be 0…{_EVNUM_MAX}, got {evnum!r}")
    if n == 0:
        return Memories(None, None)
    if n <= 9999:
        ev, mv = n, n
    else:
        ev, mv = n % 10000, n // 10000
    memories = Memories(ev if ev > 0 else None, mv)
    if sizes is not None:
        ev_size, mv_size = sizes
        if memories.ev is not None and memories.ev > ev_size:
            raise ValueError(f"evnum {n}: EV memory {memories.ev} beyond _EVMVNUM[0] = {ev_size}")
        if memories.mv is not None and memories.mv > mv_size:
            raise ValueError(f"evnum {n}: MV memory {memories.mv} beyond _EVMVNUM[1] = {mv_size}")
    return memories


# --- measuring-math §3.2 tolerance parameters --------------------------------------------------------------

@dataclass(frozen=True)
class Tolerance:
    """The tolerance parameters of manual §1.10/§2.3.11 (measuring-math §3.2, defaults of its table).

    Field names are design.md §9.3's ``params.tolerance`` keys: setpoint = _SETVAL, upper = _TUL,
    lower = _TLL, zero_range = _TZL, mean_range = _TMV, dim_difference = _TDIF,
    safe_area = _TSA, k = _K, evnum = _EVNUM, keep_mean = _CHBIT[4]; distortion_limit = _TNVL
    (CYCLE997 only). ``setpoint`` has no default in the manual; 0 suits callers that pass a
    difference as the actual value.

    Only magnitudes of _TZL, _TMV, _TDIF, _TSA, _TNVL matter (manual §2.3.11 "all these
    parameters can take any value, only the absolute values are meaningful"); _TUL/_TLL are
    signed. Validation (ValueError naming the field): every number finite; _TSA and _TDIF not 0
    (range "> 0"); _TUL ≥ _TLL (a swapped band puts every part out of tolerance); _EVNUM
    decodable (measuring-math §3.3); _K integer ≥ 1, where _K < 1 is the manual's alarm 61318 (MeasuringError,
    see ``_check_weighting``).
    """

    setpoint: float = 0.0
    upper: float = 1.0
    lower: float = -1.0
    zero_range: float = 0.001
    mean_range: float = 0.7
    dim_difference: float = 1.2
    safe_area: float = 2.0
    k: int = 1
    evnum: int = 0
    keep_mean: bool = False
    distortion_limit: float = 1.2

    def __post_init__(self) -> None:
        for name in ("setpoint", "upper", "lower", "zero_range", "mean_range", "dim_difference",
                     "safe_area", "distortion_limit"):
            object.__setattr__(self, name, checks.real(name, getattr(self, name)))
        if not isinstance(self.keep_mean, bool):
            raise ValueError(f"keep_mean must be true or false, got {self.keep_mean!r}")
        if self.safe_area == 0.0:
            raise ValueError("safe_area (_TSA) must not be 0")
        if self.dim_difference == 0.0:
            raise ValueError("dim_difference (_TDIF) must not be 0")
        if self.upper < self.lower:
            raise ValueError(f"upper (_TUL = {self.upper:g}) must not be below lower (_TLL = {self.lower:g})")
        object.__setattr__(self, "evnum", checks.integer("evnum", self.evnum))
        decode_evnum(self.evnum, sizes=None)
        object.__setattr__(self, "k", _check_weighting(self.k))

    # manual §2.3.11 symmetrisation ("the cycle moves the setpoint into the middle of the band";
    # the inputs stay, the results _OVR[0]/[8]/[12] show the modified values)
    @property
    def setpoint_eff(self) -> float:
        """SETVAL_eff = _SETVAL + (_TUL + _TLL)/2 → _OVR[0] (manual §2.3.11, measuring-math §3.2)."""
        return self.setpoint + (self.upper + self.lower) / 2.0

    @property
    def upper_eff(self) -> float:
        """TUL_eff = (_TUL − _TLL)/2 → _OVR[8] (manual §2.3.11, measuring-math §3.2)."""
        return (self.upper - self.lower) / 2.0

    @property
    def lower_eff(self) -> float:
        """TLL_eff = −(_TUL − _TLL)/2 → _OVR[12] (manual §2.3.11, measuring-math §3.2)."""
        return -(self.upper - self.lower) / 2.0

    @property
    def memories(self) -> Memories:
        """The EV/MV memory numbers of ``evnum`` (measuring-math §3.3), array sizes unchecked."""
        return decode_evnum(self.evnum, sizes=None)

    def warnings(self, scope: str = "workpiece") -> list[str]:
        """The magnitude order of manual §1.10 (measuring-math §3.2 [I]: warn otherwise).

        ``workpiece`` (tool offset): |_TZL| < |_TMV| < TUL_eff < |_TDIF| < |_TSA|;
        ``tool`` (tool measuring): |_TZL| < |_TDIF| < |_TSA|; ``calibration``: |_TZL| < |_TSA|.
        Returns one message per violated neighbour pair (empty = in order). turning.md §12 Q18:
        the default _TMV 0.7 against a lathe tolerance of a few µm is caught here.
        """
        chains = {
            "workpiece": (("zero_range (_TZL)", abs(self.zero_range)),
                          ("mean_range (_TMV)", abs(self.mean_range)),
                          ("tolerance (TUL_eff)", self.upper_eff),
                          ("dim_difference (_TDIF)", abs(self.dim_difference)),
                          ("safe_area (_TSA)", abs(self.safe_area))),
            "tool": (("zero_range (_TZL)", abs(self.zero_range)),
                     ("dim_difference (_TDIF)", abs(self.dim_difference)),
                     ("safe_area (_TSA)", abs(self.safe_area))),
            "calibration": (("zero_range (_TZL)", abs(self.zero_range)),
                            ("safe_area (_TSA)", abs(self.safe_area))),
        }
        if scope not in chains:
            raise ValueError(f"scope must be one of {sorted(chains)}, got {scope!r}")
        chain = chains[scope]
        out = []
        for (name_a, a), (name_b, b) in zip(chain, chain[1:], strict=False):
            if not a < b:
                out.append(f"{name_a} = {a:g} should be smaller than {name_b} = {b:g} "
                           f"(manual §1.10: |_TZL| < |_TMV| < tolerance < |_TDIF| < |_TSA|)")
        return out

    @classmethod
    def from_params(cls, params: Mapping[str, Any] | None, defaults: Tolerance | None = None) -> Tolerance:
        """A Tolerance from design.md §9.3's ``params.tolerance``; missing keys from ``defaults``
        (the settings), else from the manual's defaults. Unknown keys are a ValueError."""
        base = defaults if defaults is not None else cls()
        params = dict(params or {})
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(params) - known)
        if unknown:
            raise ValueError(f"unknown tolerance key(s): {', '.join(unknown)}")
        return replace(base, **params)


# --- measuring-math §3.4 mean value -------------------------------------------------------------------------

def mean_value(mv_old: float, deviation: float, k: object) -> float:
    """Mv_new = Mv_old − (Mv_old − D_i)/k — manual §1.9, seeds 000 (R29) and 004, measuring-math §3.4.

    ``deviation`` D_i is the actual/setpoint difference minus the empirical value (averaged over
    _NMSP); ``mv_old`` the mean before this measurement (0 after a compensation). k = 1 → D_i.
    """
    weight = _check_weighting(k)
    mv_old = checks.real("mv_old", mv_old)
    deviation = checks.real("deviation", deviation)
    return mv_old - (mv_old - deviation) / weight


# --- measuring-math §3.5 workpiece measuring with automatic tool offset ------------------------------------

@dataclass(frozen=True)
class Decision:
    """Outcome of the workpiece-with-tool-offset flow (manual §1.11 flowchart, measuring-math §3.5).

    - ``deviation`` D = (actual ∓ EV) − SETVAL_eff (result key ``deviation``)
    - ``mean_value`` Mv_new where the mean branch ran (5a/5b), else None (``mean_value``)
    - ``decision`` one of DECISIONS (design.md §9.3): safe_area (1), dimension_difference (2),
      oversize/undersize (3), full (4), mean (5a), none (5b)
    - ``corrected`` the deviation quantity compensated, before any halving: D (branches 3, 4),
      Mv_new (5a), 0.0 when nothing is corrected; engine.tool_offset turns it into c
    - ``alarm`` catalogue entry or None; ``abort``: the cycle aborts (NC Reset, 61303);
      ``stop``: M0 after the alarm (_CBIT[2]=1, branches 2 and 3)
    - ``mv_memory`` value to write into the MV memory, None = leave it alone (no memory in use,
      or branches 1/2); ``memory_cleared``: it is written 0 after a compensation
    - ``violation`` "safe_area" / "dimension_difference" for the _TSA/_TDIF branches, which
      the repeat rule may repeat (measuring-math §3.6); None otherwise
    - reporting: ``actual`` (averaged, raw), ``empirical_value`` (as stored), ``mv_old`` (the
      mean the formula used), ``setpoint``/``upper``/``lower`` = SETVAL_eff, TUL_eff, TLL_eff
    """

    deviation: float
    mean_value: float | None
    decision: str
    corrected: float
    alarm: AlarmDef | None
    mv_memory: float | None
    memory_cleared: bool
    violation: str | None
    actual: float
    empirical_value: float
    mv_old: float
    setpoint: float
    upper: float
    lower: float
    abort: bool = False
    stop: bool = False

    @property
    def corrects(self) -> bool:
        """True when the tool is corrected (oversize, undersize, full, mean)."""
        return self.decision in _CORRECTING

    @property
    def repeatable(self) -> bool:
        """True for the _TSA/_TDIF violations the repeat rule (measuring-math §3.6) may repeat."""
        return self.violation is not None


def _apply_ev(actual: float, ev: float, ev_add: bool) -> float:
    """The empirical value, "before all other measures": _CHBIT[5]=0 subtract (default),
    1 add — manual §1.10, §2.3.14, measuring-math §3.3."""
    return actual + ev if ev_add else actual - ev


def _memory_values(tolerance: Tolerance, ev: object, mv_old: object) -> tuple[float, float, bool]:
    """(EV, Mv_old, MV memory in use). A value for a memory _EVNUM does not select is a caller
    error. With _CHBIT[4]=0 the previous mean is 0 and nothing is stored (measuring-math §3.3 [I], measuring-math §17 Q9)."""
    memories = tolerance.memories
    ev_value = checks.real("ev", ev)
    mv_value = checks.real("mv_old", mv_old)
    if memories.ev is None and ev_value != 0.0:
        raise ValueError(f"ev = {ev_value:g} given, but evnum = {tolerance.evnum} selects no EV memory")
    if memories.mv is None and mv_value != 0.0:
        raise ValueError(f"mv_old = {mv_value:g} given, but evnum = {tolerance.evnum} selects no MV memory")
    in_use = tolerance.keep_mean and memories.mv is not None
    return ev_value, (mv_value if in_use else 0.0), in_use


def decide_tool_offset(actual: object, tolerance: Tolerance, *, ev: float = 0.0, mv_old: float = 0.0,
                       ev_add: bool = False, m0_on_alarm: bool = False) -> Decision:
    """The decision flow of manual §1.11 / measuring-math §3.5 for workpiece measuring with tool offset.

    ``actual``: the measured value (diameter/width for bores, shafts, slots, webs, rectangles;
    position for a 1-point measurement), or the _NMSP measurements of it (averaged, measuring-math §1.4).
    ``ev``: the empirical value from the EV memory, ``mv_old``: the MV memory's content (both
    0 when ``tolerance.evnum`` selects none). ``ev_add`` = _CHBIT[5], ``m0_on_alarm`` = _CBIT[2].

    In this order (the first matching branch wins):

    0. D = (actual ∓ EV) − SETVAL_eff                                   (EV first, measuring-math §3.3)
    1. |D| > |_TSA|  → safe_area, 61303, no correction, cycle aborts; repeatable (measuring-math §3.6)
    2. |D| > |_TDIF| → dimension_difference, 62306, no correction; repeatable
    3. D > TUL_eff / D < TLL_eff → oversize 62304 / undersize 62305, 100 % of D, memory cleared
    4. |D| > |_TMV|  → full, 100 % of D, memory cleared
    5. Mv_new = Mv_old − (Mv_old − D)/k   (Mv_old = 0 with _CHBIT[4]=0)   (measuring-math §3.4)
       5a. |Mv_new| > |_TZL| → mean: correct by Mv_new, memory cleared
       5b. else → none: no correction, Mv_new stored (only with _CHBIT[4]=1)
    """
    value = average(actual)
    ev, mv_prev, in_use = _memory_values(tolerance, ev, mv_old)
    d = _apply_ev(value, ev, bool(ev_add)) - tolerance.setpoint_eff        # measuring-math §3.5 D
    common: dict[str, Any] = dict(deviation=d, actual=value, empirical_value=ev, mv_old=mv_prev,
                  setpoint=tolerance.setpoint_eff, upper=tolerance.upper_eff,
                  lower=tolerance.lower_eff)
    cleared = 0.0 if in_use else None

    if abs(d) > abs(tolerance.safe_area) + EPS:                           # measuring-math §3.5 row 1
        return Decision(mean_value=None, decision="safe_area", corrected=0.0, alarm=alarms.SAFE_AREA,
                        mv_memory=None, memory_cleared=False, violation="safe_area", abort=True,
                        **common)
    if abs(d) > abs(tolerance.dim_difference) + EPS:                      # measuring-math §3.5 row 2
        return Decision(mean_value=None, decision="dimension_difference", corrected=0.0,
                        alarm=alarms.DIMENSION_DIFFERENCE, mv_memory=None, memory_cleared=False,
                        violation="dimension_difference", stop=bool(m0_on_alarm), **common)
    if d > tolerance.upper_eff + EPS or d < tolerance.lower_eff - EPS:    # measuring-math §3.5 row 3
        over = d > tolerance.upper_eff + EPS
        return Decision(mean_value=None, decision="oversize" if over else "undersize", corrected=d,
                        alarm=alarms.OVERSIZE if over else alarms.UNDERSIZE, mv_memory=cleared,
                        memory_cleared=in_use, violation=None, stop=bool(m0_on_alarm), **common)
    if abs(d) > abs(tolerance.mean_range) + EPS:                          # measuring-math §3.5 row 4
        return Decision(mean_value=None, decision="full", corrected=d, alarm=None, mv_memory=cleared,
                        memory_cleared=in_use, violation=None, **common)
    mv_new = mean_value(mv_prev, d, tolerance.k)                          # measuring-math §3.5 row 5, measuring-math §3.4
    if abs(mv_new) > abs(tolerance.zero_range) + EPS:                     # measuring-math §3.5 row 5a
        return Decision(mean_value=mv_new, decision="mean", corrected=mv_new, alarm=None,
                        mv_memory=cleared, memory_cleared=in_use, violation=None, **common)
    return Decision(mean_value=mv_new, decision="none", corrected=0.0, alarm=None,  # measuring-math §3.5 row 5b
                    mv_memory=mv_new if in_use else None, memory_cleared=False, violation=None,
                    **common)


# --- measuring-math §3.6 repeat rule ------------------------------------------------------------------------

@dataclass(frozen=True)
class RepeatAction:
    """What follows a measurement under the repeat rule (manual §9.2, measuring-math §3.6).

    ``repeat``: measure again; ``alarm``: the alarm to show now (None = none); ``m0``: stop
    with M0 and wait for NC Start before the repetition (_CBIT[1]=1); ``abort``: the cycle
    ends with an NC-Reset alarm; ``repetitions``: repetitions made once this action is done;
    ``final``: no further repetition follows.
    """

    repeat: bool
    alarm: AlarmDef | None
    m0: bool
    abort: bool
    repetitions: int
    final: bool


def repeat_measurement(violation: str | None, repetitions_done: int, *, repeat: bool = False,
                       alarm_and_m0: bool = False, abort_after_repeats: bool = True) -> RepeatAction:
    """The repeat rule of manual §9.2 (_CBIT[0], _CBIT[1]) / measuring-math §3.6.

    ``violation``: the flow's ``violation`` ("safe_area", "dimension_difference" or None) of
    the measurement just made; ``repetitions_done``: repetitions made before it (0 after the
    first measurement). ``repeat`` = _CBIT[0] (repeat, at most 4 times), ``alarm_and_m0`` =
    _CBIT[1] (alarm and M0 before each repetition).

    - no violation: go on (no repetition, no alarm from this rule);
    - _CBIT[0]=0: the flow's own alarm, at once: 61303 and abort (_TSA), 62306 and continue
      (_TDIF) (measuring-math §3.5);
    - _CBIT[0]=1 and fewer than 4 repetitions: repeat; with _CBIT[1]=1 the warning-class alarm
      62303 / 62306 is shown and M0 generated (measuring-math §3.6 [I]), with _CBIT[1]=0 silently;
    - _CBIT[0]=1 and the 4th repetition still violates: final alarm 61303 (abort); for _TDIF
      61306 (abort) where the alarm list gives it for the cycle (``abort_after_repeats``: 971,
      972, 974, 977, 978, 979, 982), else 62306 (continue, e.g. CYCLE994) (measuring-math §3.6 [I], measuring-math §17 Q11).
    """
    done = checks.integer("repetitions_done", repetitions_done)
    if done < 0 or done > MAX_REPETITIONS:
        raise ValueError(f"repetitions_done must be 0…{MAX_REPETITIONS}, got {repetitions_done!r}")
    if violation is None:
        return RepeatAction(repeat=False, alarm=None, m0=False, abort=False, repetitions=done, final=True)
    if violation not in ("safe_area", "dimension_difference"):
        raise ValueError(f"violation must be 'safe_area', 'dimension_difference' or None, got {violation!r}")
    safe = violation == "safe_area"
    if repeat and done < MAX_REPETITIONS:
        warn = (alarms.SAFE_AREA_WARNING if safe else alarms.DIMENSION_DIFFERENCE) if alarm_and_m0 else None
        return RepeatAction(repeat=True, alarm=warn, m0=bool(alarm_and_m0), abort=False,
                            repetitions=done + 1, final=False)
    if safe:
        final_alarm = alarms.SAFE_AREA
    elif repeat and abort_after_repeats:
        final_alarm = alarms.DIMENSION_DIFFERENCE_ABORT
    else:
        final_alarm = alarms.DIMENSION_DIFFERENCE
    return RepeatAction(repeat=False, alarm=final_alarm, m0=False, abort=not final_alarm.warning,
                        repetitions=done, final=True)


# --- measuring-math §3.5 tool measuring (CYCLE971) ---------------------------------------------------------

@dataclass(frozen=True)
class ToolMeasureDecision:
    """Outcome of the tool-measuring rule (manual §1.10, §5.2.1, §5.2.4; measuring-math §3.5, measuring-math §14.4).

    ``value`` = measured ∓ EV; ``stored`` = geometry + wear before; ``delta`` Δ = value − stored;
    ``decision``: safe_area (61303), dimension_difference (62306), none (|Δ| < _TZL, memory
    unchanged) or full (written); ``write``: the tool memory changes; ``geometry``/``wear``:
    the tool's values after (unchanged unless ``write``); ``violation`` as in Decision.
    """

    measured: float
    value: float
    stored: float
    delta: float
    decision: str
    alarm: AlarmDef | None
    write: bool
    geometry: float
    wear: float
    violation: str | None
    abort: bool = False


def decide_tool_measurement(measured: object, geometry: float, wear: float, tolerance: Tolerance, *,
                            remeasure: bool = False, ev: float = 0.0, ev_add: bool = False,
                            ) -> ToolMeasureDecision:
    """Tool measuring: Δ against _TSA, _TDIF ("≥"), _TZL; no mean value.

    manual §1.10 (flowchart "tool measuring"), §5.2.1/§5.2.4 (examples); measuring-math §3.5,
    measuring-math §14.4; turning §0.11 (CYCLE972/982 use the same rule).

    ``measured``: the measured length or radius (or its _NMSP measurements); ``geometry``,
    ``wear``: the tool's stored values; ``remeasure`` = _CHBIT[3]; ``ev`` from the EV memory.

    value = measured ∓ EV (_CHBIT[5]); Δ = value − (geometry + wear)             (measuring-math §14.4)
    |Δ| > |_TSA| → 61303, nothing written (cycle aborts)
    |Δ| ≥ |_TDIF| → 62306, no correction ("≥": manual examples, measuring-math §17 Q10)
    |Δ| < |_TZL| → tool memory unchanged
    else _CHBIT[3]=0: geometry := value, wear := 0;  _CHBIT[3]=1: wear += Δ       (measuring-math §14.4)
    """
    raw = average(measured)
    geometry = checks.real("geometry", geometry)
    wear = checks.real("wear", wear)
    ev = checks.real("ev", ev)
    if tolerance.memories.ev is None and ev != 0.0:
        raise ValueError(f"ev = {ev:g} given, but evnum = {tolerance.evnum} selects no EV memory")
    value = _apply_ev(raw, ev, bool(ev_add))
    stored = geometry + wear
    delta = value - stored
    common: dict[str, Any] = dict(measured=raw, value=value, stored=stored, delta=delta)
    if abs(delta) > abs(tolerance.safe_area) + EPS:
        return ToolMeasureDecision(decision="safe_area", alarm=alarms.SAFE_AREA, write=False,
                                   geometry=geometry, wear=wear, violation="safe_area", abort=True, **common)
    if abs(delta) >= abs(tolerance.dim_difference) - EPS:
        return ToolMeasureDecision(decision="dimension_difference", alarm=alarms.DIMENSION_DIFFERENCE,
                                   write=False, geometry=geometry, wear=wear,
                                   violation="dimension_difference", **common)
    if abs(delta) < abs(tolerance.zero_range) - EPS:
        return ToolMeasureDecision(decision="none", alarm=None, write=False, geometry=geometry,
                                   wear=wear, violation=None, **common)
    if remeasure:
        geometry_new, wear_new = geometry, wear + delta
    else:
        geometry_new, wear_new = value, 0.0
    return ToolMeasureDecision(decision="full", alarm=None, write=True, geometry=geometry_new,
                               wear=wear_new, violation=None, **common)


# --- measuring-math §3.5 probe calibration -----------------------------------------------------------------

@dataclass(frozen=True)
class CalibrationDecision:
    """Outcome of the calibration rule (manual §1.10, §5.3; measuring-math §3.5 [I], measuring-math §14.5).

    ``values``: the record after (old values where kept, everything old on a _TSA violation);
    ``stored`` / ``kept``: keys written / left at their old value; ``delta``: new − old per
    measured key; ``alarm`` SAFE_AREA or None; ``warnings``: e.g. the first calibration of a
    zeroed record with _TSA not above the ball radius.
    """

    values: dict[str, float]
    stored: tuple[str, ...]
    kept: tuple[str, ...]
    delta: dict[str, float]
    alarm: AlarmDef | None
    violation: str | None
    warnings: tuple[str, ...] = ()

    @property
    def decision(self) -> str:
        """safe_area, none (nothing changes) or full (at least one value stored)."""
        if self.alarm is not None:
            return "safe_area"
        return "full" if self.stored else "none"


def decide_calibration(new: Mapping[str, float], old: Mapping[str, float] | None, tolerance: Tolerance,
                       *, incremental: bool = False, ball_radius: float | None = None
                       ) -> CalibrationDecision:
    """Probe calibration (CYCLE976/973 workpiece probe, CYCLE971/972/982 tool probe).

    measuring-math §3.5, manual §1.10 flowcharts: Δ = new − old per stored value;
    any |Δ| > |_TSA| → 61303 and nothing is stored (per-value check, [I] measuring-math §17 Q4);
    |Δ| < |_TZL| → that value keeps its old value; otherwise it is stored. No EV, no mean.
    A value missing from ``old`` counts as 0: the first calibration of a zeroed record
    (manual §5.3 "preset _WP[] to 0 … program _TSA > ball radius to avoid 61303"); with
    ``ball_radius`` given such a calibration warns when |_TSA| ≤ r. ``incremental``:
    incremental tool-probe calibration, no _TZL/_TSA (manual §5.2.3, turning §0.11).
    """
    old = dict(old or {})
    new_values = {str(key): checks.real(f"new[{key}]", value) for key, value in new.items()}
    old_values = {str(key): checks.real(f"old[{key}]", value) for key, value in old.items()}
    delta = {key: value - old_values.get(key, 0.0) for key, value in new_values.items()}
    warnings: list[str] = []
    zeroed = all(old_values.get(key, 0.0) == 0.0 for key in new_values)
    if ball_radius is not None and zeroed and not incremental and abs(tolerance.safe_area) <= abs(ball_radius):
        warnings.append(f"first calibration of a zeroed record: safe_area (_TSA) = {tolerance.safe_area:g} "
                        f"must exceed the ball radius {abs(ball_radius):g} (manual §5.3)")
    if incremental:
        values = {**old_values, **new_values}
        return CalibrationDecision(values=values, stored=tuple(new_values), kept=(), delta=delta,
                                   alarm=None, violation=None, warnings=tuple(warnings))
    if any(abs(d) > abs(tolerance.safe_area) + EPS for d in delta.values()):
        return CalibrationDecision(values=dict(old_values), stored=(), kept=tuple(new_values), delta=delta,
                                   alarm=alarms.SAFE_AREA, violation="safe_area", warnings=tuple(warnings))
    values = dict(old_values)
    stored, kept = [], []
    for key, value in new_values.items():
        if abs(delta[key]) < abs(tolerance.zero_range) - EPS:
            kept.append(key)
            values.setdefault(key, 0.0)
        else:
            stored.append(key)
            values[key] = value
    return CalibrationDecision(values=values, stored=tuple(stored), kept=tuple(kept), delta=delta,
                               alarm=None, violation=None, warnings=tuple(warnings))


# --- measuring-math §3.5 workpiece measuring with ZO correction --------------------------------------------

@dataclass(frozen=True)
class ZeroOffsetDecision:
    """Outcome of the ZO rule: ``deviation`` d (a float, or a tuple per axis as given),
    ``decision`` full / safe_area, ``corrected`` = d (100 %) or zeros, ``alarm``."""

    deviation: float | tuple[float, ...]
    decision: str
    corrected: float | tuple[float, ...]
    alarm: AlarmDef | None
    violation: str | None
    abort: bool = False


def decide_zero_offset(actual: float | Sequence[float], setpoint: float | Sequence[float], safe_area: float, *, ev: float = 0.0,
                       ev_add: bool = False) -> ZeroOffsetDecision:
    """Workpiece measuring with ZO correction: only _TSA (manual §1.10 flowchart, measuring-math §3.5).

    d = (actual ∓ EV) − setpoint (EV only meaningful for 1-point CYCLE978/974, measuring-math §3.3; no
    _TUL/_TLL, so no symmetrisation, turning §5.4). ``actual``/``setpoint``: numbers, or
    sequences per axis (e.g. a centre): any |d_i| > |_TSA| → 61303, nothing corrected;
    otherwise 100 % of d into the frame. No _TZL, no mean.
    """
    tsa = checks.real("safe_area", safe_area)
    if tsa == 0.0:
        raise ValueError("safe_area (_TSA) must not be 0")
    ev = checks.real("ev", ev)
    if checks.is_number(actual):
        d = _apply_ev(checks.real("actual", actual), ev, bool(ev_add)) - checks.real("setpoint", setpoint)
        if abs(d) > abs(tsa) + EPS:
            return ZeroOffsetDecision(deviation=d, decision="safe_area", corrected=0.0,
                                      alarm=alarms.SAFE_AREA, violation="safe_area", abort=True)
        return ZeroOffsetDecision(deviation=d, decision="full", corrected=d, alarm=None, violation=None)
    acts = [checks.real("actual", a) for a in cast(Sequence[object], actual)]     # not a number: per axis
    sets = ([checks.real("setpoint", setpoint)] * len(acts) if checks.is_number(setpoint)
            else [checks.real("setpoint", s) for s in cast(Sequence[object], setpoint)])
    if len(sets) != len(acts) or not acts:
        raise ValueError("actual and setpoint must have the same, non-zero length")
    ds = tuple(_apply_ev(a, ev, bool(ev_add)) - s for a, s in zip(acts, sets, strict=True))
    if any(abs(x) > abs(tsa) + EPS for x in ds):
        return ZeroOffsetDecision(deviation=ds, decision="safe_area", corrected=(0.0,) * len(ds),
                                  alarm=alarms.SAFE_AREA, violation="safe_area", abort=True)
    return ZeroOffsetDecision(deviation=ds, decision="full", corrected=ds, alarm=None, violation=None)

