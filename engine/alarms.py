"""The alarm catalogue: every alarm the product raises, in one place.

Numbers and texts are the manual's (seed 001 jog-measuring §11 "measuring cycle alarms", translated in
spec/jog-measuring.md §10 and spec/turning.md §8); the Chinese text is the manual's own.
61000-61999 are cleared by NC Reset and abort the block; 62000-62999 are display-only
warnings cleared with Cancel (manual §11). The machine's own alarms (limit switch, Reset
abort) are in the NC's range. Code everywhere refers to the names, never to the numbers.

The catalogue is pure data and lives at the bottom of the import order (design.md §2), so the
engine, the simulator and the app can all use it.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class AlarmDef:
    """One alarm of the catalogue. ``resettable``: NC Reset (61xxx) or Cancel (62xxx) clears it."""

    number: int
    name: str
    text: str                 # the manual's text, English
    text_zh: str              # the manual's text, Chinese (seed 001 jog-measuring §11)
    remedy: str               # what the operator does about it
    resettable: bool = True

    @property
    def warning(self) -> bool:
        """62xxx: display only, the program goes on (manual §11)."""
        return 62000 <= self.number <= 62999

    def __int__(self) -> int:
        return self.number


_CATALOGUE: dict[str, AlarmDef] = {}


def _define(number: int, name: str, text: str, text_zh: str, remedy: str, *,
            resettable: bool = True) -> AlarmDef:
    alarm = AlarmDef(number, name, text, text_zh, remedy, resettable)
    if name in _CATALOGUE:
        raise ValueError(f"alarm name {name} defined twice")
    _CATALOGUE[name] = alarm
    return alarm


# --- the NC's own alarms (raised by the machine) ------------------------------------------------
RESET_ABORT = _define(
    16900, "RESET_ABORT", "Motion aborted by Reset", "复位中断运动",
    "Informational: the motion was stopped by Reset. Start the measurement again.")
SOFTWARE_LIMIT = _define(
    21614, "SOFTWARE_LIMIT", "Software limit switch", "软件限位开关",
    "Jog the axis back into its travel range, then press Reset.")

# --- measuring cycle alarms 61xxx (NC Reset) ----------------------------------------------------
SYSTEM_FRAME_MISSING = _define(
    61016, "SYSTEM_FRAME_MISSING", "System frame for cycles missing", "缺少用于循环的系统框架",
    "Commissioning: set MD 28082 MM_SYSTEM_FRAME_MASK bit 5 = 1.")
TOOL_PROBE_DIAMETER = _define(
    61230, "TOOL_PROBE_DIAMETER", "Tool probe diameter too small", "刀具测量头的直径太小",
    "Enter the effective diameter of the tool probe (E_MESS_MT_DL / E_MESS_MT_DR in the settings, "
    "or the disc diameter in the tool probe data).")
PROBE_NOT_SWITCHED = _define(
    61301, "PROBE_NOT_SWITCHED", "Probe not switched", "测量头未接通",
    "Check the measuring input; check the measuring path; the probe may be defective.")
PROBE_COLLISION = _define(
    61302, "PROBE_COLLISION", "Probe collision", "测量头-碰撞",
    "An obstacle lies in the traverse path. Jog the probe clear, press Reset, choose another start.")
PROBE_BROKEN = _define(
    61302, "PROBE_BROKEN", "Probe collision: overtravel beyond the permissible deflection", "测量头-碰撞",
    "The stylus is damaged. Change the probe (tool change), then calibrate it again.",
    resettable=False)
SAFE_AREA = _define(
    61303, "SAFE_AREA", "Safe area exceeded", "超出置信区域",
    "Check the setpoints and the probe; enlarge the safe area _TSA if the deviation is real.")
DIMENSION_DIFFERENCE_ABORT = _define(
    61306, "DIMENSION_DIFFERENCE_ABORT", "Permissible dimensional difference exceeded",
    "超出允许的尺寸差值", "Check the setpoint and the tool; enlarge _TDIF if the deviation is real.")
WRONG_VARIANT = _define(
    61307, "WRONG_VARIANT", "Wrong measuring variant", "错误的测量方案",
    "The value of _MVAR is not allowed for this cycle: correct the call.")
MEASURING_PATH = _define(
    61308, "MEASURING_PATH", "Check measuring path 2a", "检查测量路径 2a",
    "The measuring path _FA must be greater than 0.")
PROBE_TYPE = _define(
    61309, "PROBE_TYPE", "Check probe type", "检查测量头类型",
    "Load the workpiece probe (tool type 710) into the spindle.")
SCALE_FACTOR = _define(
    61310, "SCALE_FACTOR", "Scale factor active", "比例尺系数有效",
    "Measuring is not possible with active scaling: deselect the scale factor.")
NO_D_NUMBER = _define(
    61311, "NO_D_NUMBER", "No D number active", "没有D号码有效",
    "Load the tool to be measured (with its offset) into the spindle.")
PROBE_NUMBER = _define(
    61313, "PROBE_NUMBER", "Check probe number", "检查测量头号码",
    "Correct the probe number _PRNUM or create the probe data record.")
TOOL_TYPE = _define(
    61314, "TOOL_TYPE", "Check selected tool type", "检查所选择的刀具类型",
    "The tool in the spindle may not be measured this way (e.g. the workpiece probe): load a cutter.")
CUTTING_EDGE_POSITION = _define(
    61315, "CUTTING_EDGE_POSITION", "Check cutting edge position", "检查切削位置",
    "Check the cutting edge position SL of the tool (probe) in the tool data.")
CIRCLE_UNDETERMINED = _define(
    61316, "CIRCLE_UNDETERMINED", "Centre and radius cannot be determined", "无法测得中点和半径",
    "The touches do not define a circle: check the start position and the diameter.")
CIRCLE_PARAMETERS = _define(
    61317, "CIRCLE_PARAMETERS", "Check parameters CYCLE116", "检查参数CYCLE116",
    "A circle needs 3 or 4 touches around the centre.")
WEIGHTING_FACTOR = _define(
    61318, "WEIGHTING_FACTOR", "Check weighting factor _K", "检查加权函数_K",
    "The weighting factor k of the mean value must not be 0.")
TOOL_NUMBER = _define(
    61320, "TOOL_NUMBER", "Check tool number", "检查刀具号码",
    "The tool to be corrected does not exist: check the tool number.")
ZO_NUMBER = _define(
    61321, "ZO_NUMBER", "Check ZO memory number", "检查NV存储器号码",
    "The zero offset named for the correction does not exist or may not be written.")
KNUM_DIGIT4 = _define(
    61322, "KNUM_DIGIT4", "Check 4th digit of _KNUM", "检查_KNUM的第4个数字",
    "Correct the 4th digit of _KNUM (and check _MVAR).")
KNUM_DIGIT5 = _define(
    61323, "KNUM_DIGIT5", "Check 5th digit of _KNUM", "检查_KNUM的第5个数字",
    "Correct the 5th digit of _KNUM (and check _MVAR).")
KNUM_DIGIT6 = _define(
    61324, "KNUM_DIGIT6", "Check 6th digit of _KNUM", "检查_KNUM的第6个数字",
    "Correct the 6th digit of _KNUM (and check _MVAR).")
MEASURING_AXIS = _define(
    61325, "MEASURING_AXIS", "Check measuring axis / offset axis", "检查测量轴/位移轴",
    "The measuring axis _MA has a wrong value.")
MEASURING_DIRECTION = _define(
    61326, "MEASURING_DIRECTION", "Check measuring direction", "检查测量方向",
    "The measuring direction _MD has a wrong value.")
PROGRAM_RESET = _define(
    61327, "PROGRAM_RESET", "Program reset required", "需要进行程序复位", "Press Reset.")
D_NUMBER = _define(
    61328, "D_NUMBER", "Check D number", "检查D号码", "The D number in _KNUM is 0.")
ROTARY_AXIS = _define(
    61329, "ROTARY_AXIS", "Check rotary axis", "检查圆轴",
    "The axis named for the angle correction is not a rotary axis of this machine.")
ROTATION_ACTIVE = _define(
    61330, "ROTATION_ACTIVE", "Coordinate rotation active", "坐标旋转有效",
    "Measuring is not possible in a rotated coordinate system: deselect the rotation.")
TOOL_TIP_POSITION = _define(
    61332, "TOOL_TIP_POSITION", "Change tool tip position", "更改刀尖位置",
    "The tool's position is not unambiguous: change the start point of the measurement.")
CALIBRATION_BODY = _define(
    61333, "CALIBRATION_BODY", "Check calibration body number", "检查校准头号码",
    "Check the calibration body (groove) number and its data.")
PROTECTION_ZONE = _define(
    61334, "PROTECTION_ZONE", "Check protection zone", "检查保护区域",
    "The protection zone parameters _SZA/_SZO are too large or too small.")
NO_GEOMETRY_AXIS = _define(
    61336, "NO_GEOMETRY_AXIS", "No geometry axis", "不存在几何轴",
    "Commissioning: check MD 20060.")
POSITIONING_VELOCITY = _define(
    61338, "POSITIONING_VELOCITY", "Positioning velocity zero", "定位速度为零",
    "Set the positioning feeds (_SPEED[1], _SPEED[2]) above 0.")
RAPID_REDUCTION = _define(
    61339, "RAPID_REDUCTION", "Rapid traverse reduction factor < 0", "补偿系数 快速速度< 0",
    "Check _SPEED[0].")
NOT_CALIBRATED_IN_PLANE = _define(
    61341, "NOT_CALIBRATED_IN_PLANE", "Probe not calibrated in active plane", "未校准有效平面中的测量头",
    "Calibrate the probe in the active plane before measuring.")
NO_TOOL_FOR_IDENTIFIER = _define(
    61343, "NO_TOOL_FOR_IDENTIFIER", "No tool for the given tool identifier", "对于所给定的WZ标志不存在刀具",
    "Check the tool number or name; the tool must be in the magazine.")
SEVERAL_TOOLS = _define(
    61344, "SEVERAL_TOOLS", "Several tools active", "有多个有效的刀具",
    "Remove the tools from the other spindles.")
D_NUMBER_TOO_HIGH = _define(
    61345, "D_NUMBER_TOO_HIGH", "Parameterised D number (_KNUM) too high", "参数化的D号码(_KNUM)过大",
    "Reduce the D number in _KNUM.")
TOOL_PROBE_DZ_ZERO = _define(
    61349, "TOOL_PROBE_DZ_ZERO", "Distance probe upper edge to measuring position is 0",
    "在进行刀具半径测量时，测量头上棱到测量位置的距离为0",
    "Set the distance from the probe's upper edge to the measuring position (E_MESS_MT_DZ).")
TOOL_SIZE_ZERO = _define(
    61351, "TOOL_SIZE_ZERO", "Tool length or radius is 0", "刀具长度或半径为0",
    "Enter the approximate length and radius of the tool in the tool data.")
DISTANCE_P1_P2 = _define(
    61364, "DISTANCE_P1_P2", "Check distance measuring point 1 to measuring point 2",
    "检查测量点1到测量点2的距离", "The distance _ID must be greater than 0.")
POINTS_IDENTICAL = _define(
    61367, "POINTS_IDENTICAL", "Points P1 and P2 or P3 and P4 identical", "点P1和P2或者P3和P4同一",
    "Measure the points of one edge at different places.")
NO_INTERSECTION = _define(
    61368, "NO_INTERSECTION", "Lines through P1/P2 or P3/P4 have no intersection",
    "由点P1和P2或者P3和P4所确定的直线没有切点", "The two edges are parallel: measure two edges that meet.")
CORNER_NOT_UNIQUE = _define(
    61369, "CORNER_NOT_UNIQUE", "Corner position cannot be determined uniquely",
    "不能清楚确定角的位置，检查参数_SETV[0...7]",
    "The edges' intersection lies between the points of one edge: measure both points to one side.")
NEEDS_SPOS = _define(
    61372, "NEEDS_SPOS", "Selected measuring variant needs an SPOS-capable spindle",
    "选出的测量方案需要有SPOS能力的主轴", "Change the measuring variant or check the machine configuration.")
MONO_PROBE_SPOS = _define(
    61373, "MONO_PROBE_SPOS", "Mono probe needs an SPOS-capable spindle", "单测量头需要有SPOS能力的主轴",
    "Check the machine configuration.")
NOT_SWITCHED_LIMITED = _define(
    61401, "NOT_SWITCHED_LIMITED", "Probe not switched, traverse path limited by software limit switch",
    "未接通测量头，通过软件限位开关进行运行路径限制",
    "The setpoint position cannot be reached within the software limits.")
COLLISION_LIMITED = _define(
    61402, "COLLISION_LIMITED", "Probe collision, traverse path limited by software limit switch",
    "测量头碰撞，通过软件限位开关进行运行路径限制", "Reposition the probe within the software limits.")
FRAME_INTERNAL = _define(
    61403, "FRAME_INTERNAL", "Internal cycle error in frame calculation", "框架计算时的内部循环故障",
    "Internal error of the frame calculation: report it with the measurement log entry.")
TOOL_OFFSET_INTERNAL = _define(
    61404, "TOOL_OFFSET_INTERNAL", "Internal cycle error in tool offset calculation", "WZ校正时的内部循环故障",
    "Check the dependent tool data.")
FRAME_IMPOSSIBLE = _define(
    61411, "FRAME_IMPOSSIBLE", "Frame calculation impossible, check values", "无法进行框架运算，检查数值",
    "The points do not define a plane: measure three points that are not on one line.")
BASIC_FRAME_MISSING = _define(
    61412, "BASIC_FRAME_MISSING", "Channel basic frame does not exist", "通道基准框架不存在",
    "Commissioning: set MD 28081 > 0 and $P_CHBFRMASK > 0.")
SPHERE_DIAMETER = _define(
    61413, "SPHERE_DIAMETER", "Check setpoint of sphere diameter, _SETVAL <= 0", "检查球直径额定值， _SETVAL <=0",
    "Enter the sphere diameter (greater than 0).")
TRIANGLE_DISTORTION = _define(
    61414, "TRIANGLE_DISTORTION", "Triangle distortion limit exceeded", "三角变形超出界限",
    "Check the setpoints and actual values of the three spheres (_TNVL).")
PROBE_PLANE = _define(
    61415, "PROBE_PLANE", "Check probe / working plane", "检查测量头/加工平面",
    "Use a probe allowed for the working plane, or change the working plane.")
RECORD_COUNT = _define(
    61416, "RECORD_COUNT", "Adapt record count _TP[]/_CVAL", "匹配区大小 _TP[ ]/_CVAL",
    "Adapt the number of probe data records.")
# product extensions of the CYCLE996-like kinematics measurement (design.md §10.6; numbers of this
# product, not of the manual's catalogue)
KINEMATICS_SPHERE = _define(
    61470, "KINEMATICS_SPHERE", "Calibration sphere: measured diameter outside the tolerance",
    "校准球：测得的直径超出公差",
    "Clean the calibration sphere and the probe ball, check the sphere diameter entered, measure again.")
KINEMATICS_AXIS = _define(
    61471, "KINEMATICS_AXIS", "Rotary axis cannot be determined from these positions", "无法由这些位置确定回转轴",
    "Measure at 3 or more different positions of the axis, spread over a wider angle.")

# --- warnings 62xxx (Cancel, the program goes on) ----------------------------------------------
SAFE_AREA_WARNING = _define(
    62303, "SAFE_AREA_WARNING", "Safe area exceeded", "超出置信区域",
    "Check the setpoints; enlarge the safe area _TSA.")
OVERSIZE = _define(
    62304, "OVERSIZE", "Oversize", "尺寸余量",
    "The deviation is above the upper tolerance: the tool was corrected by 100 %; check the part.")
UNDERSIZE = _define(
    62305, "UNDERSIZE", "Undersize", "尺寸不足",
    "The deviation is below the lower tolerance: the tool was corrected by 100 %; check the part.")
DIMENSION_DIFFERENCE = _define(
    62306, "DIMENSION_DIFFERENCE", "Permissible dimensional difference exceeded", "超出允许的尺寸差值",
    "The tool was not corrected: check whether it is worn or broken; enlarge _TDIF if the deviation is real.")


def all_alarms() -> tuple[AlarmDef, ...]:
    """Every alarm of the catalogue, by number."""
    return tuple(sorted(_CATALOGUE.values(), key=lambda a: (a.number, a.name)))


def by_name(name: str) -> AlarmDef:
    return _CATALOGUE[name]


def by_number(number: int) -> AlarmDef | None:
    """The catalogue entry for ``number`` (the resettable one where two share it), or None."""
    matches = [a for a in _CATALOGUE.values() if a.number == int(number)]
    matches.sort(key=lambda a: not a.resettable)
    return matches[0] if matches else None


# --- the part-program interpreter (app/nc, design.md §9.4) --------------------------------------
# NCK channel alarms of the 840D language (numbers as the 840D diagnostics manual lists them; seed
# 001 only lists the cycle alarms). They abort the program like a cycle alarm (NC Reset).
NC_FEED_MISSING = _define(
    10860, "NC_FEED_MISSING", "Feedrate not programmed", "未编程进给率",
    "Program a feed F greater than 0 before (or in) the first G1 or measuring block.")
NC_SYNTAX = _define(
    12080, "NC_SYNTAX", "Syntax error", "语法错误",
    "Correct the block at the position shown (see the message), then start the program again.")
NC_G_FUNCTION_UNKNOWN = _define(
    12470, "NC_G_FUNCTION_UNKNOWN", "G function is unknown", "未知的G功能",
    "This control knows G0 G1 G17-G19 G53 G54-G57 G500 G505-G599 G70 G71 G700 G710 G90 G91 "
    "G94 G95 G100-G102 and SUPA: correct the G function.")
NC_NAME_UNKNOWN = _define(
    12550, "NC_NAME_UNKNOWN", "Name not defined or option not available", "名称未定义或选件不存在",
    "Check the spelling of the variable, function or cycle name; define local variables with DEF.")
NC_ARITHMETIC = _define(
    14051, "NC_ARITHMETIC", "Arithmetic error in part program", "零件程序中的算术错误",
    "Check the expression: division by zero, square root of a negative number, a value out of range.")
NC_JUMP_TARGET = _define(
    14080, "NC_JUMP_TARGET", "Jump destination not found", "未找到跳转目标",
    "The label or block number of GOTOF/GOTOB/GOTO does not exist in the search direction.")
NC_ARRAY_INDEX = _define(
    17020, "NC_ARRAY_INDEX", "Illegal array index", "非法的数组索引",
    "The index lies outside the variable's declared size: correct the index.")
NC_WRITE_PROTECTED = _define(
    17070, "NC_WRITE_PROTECTED", "Data is write-protected", "数据写保护",
    "System variables such as $AA_MM are written by the control only; assign a user variable instead.")
NC_D_NUMBER = _define(
    17180, "NC_D_NUMBER", "Illegal D number", "非法的D号",
    "The tool has no cutting edge with this D number: correct D or the tool data.")
# Product-defined (840D user alarm range 65000-69999): G100-G102 are measuring functions of another
# control (seed 003), the 840D has no alarm numbers for them.
NO_MEASURED_VALUE = _define(
    65100, "NO_MEASURED_VALUE", "No measured value for the measuring offset", "没有用于测量偏移的测量值",
    "G101 includes a measured value of a preceding G100 measuring move: measure the axis with G100 first.")
NO_MEASURING_OFFSET = _define(
    65101, "NO_MEASURING_OFFSET", "No measuring offset included for the axis", "该轴没有计入测量偏移",
    "G102 removes what G101 included: program G102 only for axes with an included measuring offset.")
NO_MEASURING_PATH = _define(
    65102, "NO_MEASURING_PATH", "Measuring move without traverse path", "测量运动没有运行路径",
    "The probe is already at the programmed position: start the measuring move in front of the surface.")
NC_VALUE_RANGE = _define(
    65103, "NC_VALUE_RANGE", "Programmed value out of range", "编程值超出范围",
    "Correct the value shown in the message (sign, integer, size or range).")
NC_RUNAWAY = _define(
    65104, "NC_RUNAWAY", "Program runaway stopped: loop limit or watchdog", "程序失控已停止：循环上限或看门狗",
    "The program repeats a jump without end or computes too long without moving: correct the loop's "
    "condition, then press Reset.")
NC_INTERNAL = _define(
    65199, "NC_INTERNAL", "Internal error of the part-program interpreter", "零件程序解释器内部错误",
    "Note the block and the message, press Reset and report it.")

# Product-defined: the start guard (issue 24 §1, design.md §10.1). Nothing has moved; the probe is intact.
START_GUARD_COLLISION = _define(
    65300, "START_GUARD_COLLISION", "Start guard: the planned path would run into material",
    "启动保护：计划路径会撞到材料",
    "Nothing moved. Position the probe as the measuring screen's picture shows (above the feature, "
    "clear of it) or correct the parameters named in the message, then press NC Start again.")
START_GUARD_LIMIT = _define(
    65301, "START_GUARD_LIMIT", "Start guard: the planned path leaves the travel range",
    "启动保护：计划路径超出行程范围",
    "Nothing moved. Start the measurement farther from the axis limits, or shorten the measuring path.")
START_GUARD_OVERTRAVEL = _define(
    65302, "START_GUARD_OVERTRAVEL", "Start guard: braking would push the probe beyond its permissible deflection",
    "启动保护：制动会使测量头超出允许偏转",
    "Nothing moved. Lower the measuring feed or the feed override until the braking distance stays within "
    "the probe's permissible deflection, then press NC Start again.")
# --- probe state at NC Start (design.md §10.4) ----------------------------------------------------
# Product-defined (840D user alarm range): a measuring task starts only with a probe that can switch.
PROBE_NOT_ARMED = _define(
    65400, "PROBE_NOT_ARMED", "Probe not ready: it is not switched on", "测量头未就绪：未开启",
    "Switch the probe on (radio probe: check or change its battery), press Reset, then NC Start again.")
PROBE_DEFLECTED = _define(
    65401, "PROBE_DEFLECTED", "Probe deflected before the start", "启动前测量头已偏转",
    "Jog the probe clear of the surface and check that the stylus sits free, press Reset, then NC Start again.")
PROBE_NOT_IN_SPINDLE = _define(
    65402, "PROBE_NOT_IN_SPINDLE", "The probe is not the tool in the spindle", "测量头不是主轴中的刀具",
    "Load the workpiece probe into the spindle (tool change), press Reset, then NC Start again.")
TOOL_PROBE_NOT_ARMED = _define(
    65403, "TOOL_PROBE_NOT_ARMED", "Tool probe not ready: it is not switched on", "刀具测量头未就绪：未开启",
    "Switch the tool probe on (radio probe: check or change its battery), press Reset, then NC Start again.")
TOOL_PROBE_DEFLECTED = _define(
    65404, "TOOL_PROBE_DEFLECTED", "Tool probe deflected before the start", "启动前刀具测量头已偏转",
    "Move the tool clear of the tool probe and check that its disc sits free, press Reset, then NC Start again.")

# --- turning cycles: alarms of spec/turning.md §8 the catalogue lacked (seed 001 [L28123–L28133]) ---
TOOL_ENVIRONMENT = _define(
    61405, "TOOL_ENVIRONMENT", "Tool environment in _TENV does not exist", "_TENV中刀具范围不存在",
    "Correct the name in _TENV or create that tool environment.")
DL_NUMBER = _define(
    61406, "DL_NUMBER", "Check DL number in _DLNUM", "在_DLNUM中检查DL号码",
    "The setup/sum offset number _DLNUM must be 0..6 (1..6 where _KNUM asks for one).")
KNUM_DIGIT7 = _define(
    61407, "KNUM_DIGIT7", "Check 7th and higher digits of _KNUM", "检查_KNUM的第7个字符和更高位",
    "Correct the 7th digit of _KNUM (0..3); _KNUM has no higher digits.")
SUM_OFFSET_MISSING = _define(
    61408, "SUM_OFFSET_MISSING", "Sum offset does not exist", "总量校正不存在",
    "Commissioning: set MD 18080 bit 8 = 1 (sum offsets), or correct _KNUM/_DLNUM.")
SETUP_OFFSET_MISSING = _define(
    61409, "SETUP_OFFSET_MISSING", "Setup offset does not exist", "建立校正不存在",
    "Commissioning: set MD 18112 bit 4 = 1 (setup offsets), or correct _KNUM/_DLNUM.")
OFFSET_OPTION = _define(
    61410, "OFFSET_OPTION", "Option or offset size does not exist", "选项或校正大小不存在",
    "The offset to be corrected needs an option or larger machine data values.")

# --- a real controller behind the Machine Protocol (design.md §9.6) ------------------------------
# Product-defined: an error the controller itself reports that no catalogue entry names (LinuxCNC's
# error channel: its message is the alarm text), or a controller that stopped answering.
CONTROLLER_ERROR = _define(
    65200, "CONTROLLER_ERROR", "Controller error", "控制器故障",
    "The controller reported an error (its message is the alarm text): correct the cause, then press Reset.")

# --- logging measuring results, CYCLE100..CYCLE118 (manual §7.1, §11; spec measuring-math §15) -----
PROTOCOL_NO_FILE = _define(
    61354, "PROTOCOL_NO_FILE", "No data block found for the log file", "未找到用于记录文件的数据块",
    "Give the log file a name in _PROTNAME[1] before CYCLE100.")
PROTOCOL_FILE_TYPE = _define(
    61355, "PROTOCOL_FILE_TYPE", "Wrong data block type for the log file", "用于记录文件的错误数据块类型",
    "Name the log file with letters, digits and _, starting with two letters or a letter and _.")
PROTOCOL_JOB = _define(
    61360, "PROTOCOL_JOB", "Log job not defined - continue with Reset", "未定义记录任务——按复位键继续",
    "Switch logging on with CYCLE100 first, and call CYCLE105/CYCLE106 with a valid parameter.")
PROTOCOL_VALUE = _define(
    61361, "PROTOCOL_VALUE", "Variable cannot be logged", "不能记录变量",
    "Log only _OVR[n], _OVI[n], R parameters, _TXT[n], _TIME, _AXIS, _AXIS1..3 or text in _PROTVAL[2..5].")
PROTOCOL_COUNT = _define(
    61362, "PROTOCOL_COUNT", "Number of values too large", "数量值过大",
    "CYCLE118 formats at most 10 values: reduce its 4th parameter.")
PROTOCOL_LINE_LONG = _define(
    62307, "PROTOCOL_LINE_LONG", "Maximum number of characters per line exceeded", "超过每行的最大字符数",
    "Raise the characters per line in _PROTFORM[1].")
PROTOCOL_VARIABLE_WIDTH = _define(
    62308, "PROTOCOL_VARIABLE_WIDTH", "Variable column width not possible", "可变栏宽不可实现",
    "Give the column titles in _PROTVAL[0]; the log uses a fixed width of 12 characters meanwhile.")
PROTOCOL_COLUMN_WIDTH = _define(
    62309, "PROTOCOL_COLUMN_WIDTH", "Column width insufficient", "栏宽不足",
    "Widen the columns in _PROTFORM[5] or, with variable widths, the titles in _PROTVAL[0].")
PROTOCOL_LINE_LIMIT = _define(
    62310, "PROTOCOL_LINE_LIMIT", "Max. characters per line limited to 200", "每行最大字符数被限制为每行200个字符",
    "Set _PROTFORM[1] to at most 200.")
# 65600..65619: this product's numbers for the manual's messages that have none (manual §7.1.2)
PROTOCOL_NEW_NAME = _define(
    65600, "PROTOCOL_NEW_NAME", "Please give a new log name", "请给定新的记录名称",
    "The log file and its 9 continuation files are full: set a new name in _PROTNAME[1] and start again.")
PROTOCOL_CONTINUED = _define(
    65601, "PROTOCOL_CONTINUED", "New log file created", "已编制新的记录数据",
    "Informational: the log goes on in a continuation file (name with _ appended).")

# --- probe health (issue [probe-health], design.md §10.4): product-defined, 65120-65139 -----------
PROBE_NOT_CALIBRATED = _define(
    65120, "PROBE_NOT_CALIBRATED", "Probe not calibrated for this measurement", "测量头未针对此测量校准",
    "Calibrate the probe: the length on a known surface, the radius in the ring gauge.")
CALIBRATION_INVALID = _define(
    65121, "CALIBRATION_INVALID", "Probe calibration no longer valid", "测量头校准已失效",
    "Calibrate the probe again (the probe data screen says what made the calibration invalid).")
REPEATABILITY_EXCEEDED = _define(
    65122, "REPEATABILITY_EXCEEDED", "Probe repeatability above the limit", "测量头重复性超出极限",
    "Clean the probe ball and the surface, check that the stylus is tight, then run the repeatability "
    "check again.")
