"""PX4's fixed-wing tuning names, read and written as the vehicle's own gains.

QGroundControl 4.4 and 5 give a PX4 fixed wing a Tuning page of two tabs of sliders
(src/AutoPilotPlugins/PX4/PX4TuningComponentPlaneRate.qml: FW_RR_*, FW_PR_*, FW_YR_* and
FW_RLL_TO_YAW_FF; PX4TuningComponentPlaneAttitude.qml: FW_R_TC, FW_P_TC). PX4 flies a
cascade: the attitude error over the time constant is a rate setpoint, which a rate loop
(P, I, D, feed-forward) turns into a surface. The vehicle's roll and pitch loops
(``companion.control.laws.attitude``) are one loop each,
``surface = k·(RLL_P·error − RLL_D·rate) + ∫ k·RLL_I·error``, which is that cascade
without a rate feed-forward or derivative: rate gain RLL_D and attitude gain RLL_P / RLL_D.
So, with ``companion.params.alias`` doing the arithmetic both ways:
- FW_RR_P = RLL_D, FW_PR_P = PTCH_D (surface per rad/s of rate error);
- FW_R_TC = RLL_D / RLL_P, FW_P_TC = PTCH_D / PTCH_P (s; written, it moves RLL_P / PTCH_P);
- FW_RR_I = RLL_I · FW_R_TC (PX4 integrates the rate error, which in a steady state is the
  attitude error over the time constant), FW_PR_I likewise; FW_RR_IMAX = RLL_IMAX;
- FW_YR_P = YAW_DAMP (rudder per rad/s of yaw-rate error: the turn-coordinating damper).
The page's other sliders are terms the vehicle's loops do not have: FW_RR_D, FW_PR_D,
FW_YR_D (rate derivative), FW_RR_FF, FW_PR_FF, FW_YR_FF (rate feed-forward), FW_YR_I (yaw
integrator), FW_RLL_TO_YAW_FF (aileron-to-rudder mixing). Each is declared as the fact it
is, fixed at 0: undeclared, QGroundControl would stop the page with its "Parameters are
missing" dialog; declared, the page opens, reads 0, and a slider moved is refused with a
status text and snaps back.

The PX4 1.15 names of the guidance and energy controllers a PX4 user tunes by (no page of
4.4 or 5 reads them) are aliases too, where ``companion.control.laws.tecs`` has the same
term (its throttle damping is scaled by 4 and its pitch integrator by 3 inside the law).
"""

from __future__ import annotations

from companion.params import ParamDecl
from companion.params.alias import Alias


def _same(name: str, own: str, doc: str, unit: str = "", scale: float = 1.0) -> ParamDecl:
    """The owner's value (times ``scale``) under PX4's name; range and default follow."""
    times = f" x {scale:g}" if scale != 1.0 else ""
    return ParamDecl(name, 0.0, unit=unit, doc=f"{doc} (= {own}{times})",
                     alias=Alias((own,), scale))  # fmt: skip


def _time_constant(name: str, p: str, d: str, axis: str) -> ParamDecl:
    doc = f"{axis} attitude time constant (= {d} / {p}; written, it sets {p})"
    return ParamDecl(name, 0.0, 0.0, unit="s", doc=doc, alias=Alias((p,), times=d, inverse=True))


def _integrator(name: str, i: str, p: str, d: str, axis: str) -> ParamDecl:
    doc = f"{axis} rate integrator gain (= {i} x {d} / {p}; written, it sets {i})"
    return ParamDecl(name, 0.0, 0.0, doc=doc, alias=Alias((i,), times=d, divisor=p))


RATE_ALIASES = (
    _same("FW_RR_P", "RLL_D", "Roll rate gain: aileron per rad/s of roll-rate error"),
    _integrator("FW_RR_I", "RLL_I", "RLL_P", "RLL_D", "Roll"),
    _same("FW_RR_IMAX", "RLL_IMAX", "Roll integrator limit (aileron fraction)"),
    _same("FW_PR_P", "PTCH_D", "Pitch rate gain: elevator per rad/s of pitch-rate error"),
    _integrator("FW_PR_I", "PTCH_I", "PTCH_P", "PTCH_D", "Pitch"),
    _same("FW_PR_IMAX", "PTCH_IMAX", "Pitch integrator limit (elevator fraction)"),
    _same("FW_YR_P", "YAW_DAMP", "Yaw rate gain: rudder per rad/s of yaw-rate error"),
    _time_constant("FW_R_TC", "RLL_P", "RLL_D", "Roll"),
    _time_constant("FW_P_TC", "PTCH_P", "PTCH_D", "Pitch"),
)
LIMIT_ALIASES = (
    _same("FW_R_LIM", "ROLL_LIMIT_DEG", "Largest bank angle", "deg"),
    _same("FW_P_LIM_MAX", "PTCH_LIM_MAX_DEG", "Largest nose-up pitch", "deg"),
    _same("FW_P_LIM_MIN", "PTCH_LIM_MIN_DEG", "Largest nose-down pitch", "deg"),
    _same("FW_THR_TRIM", "TRIM_THROTTLE", "Throttle for level flight at cruise speed", "norm"),
    _same("FW_THR_MIN", "THR_MIN", "Least throttle in flight", "norm"),
    _same("FW_THR_MAX", "THR_MAX", "Most throttle", "norm"),
)
GUIDANCE_ALIASES = (
    _same("NPFG_PERIOD", "NAVL1_PERIOD", "Lateral guidance period", "s"),
    _same("NPFG_DAMPING", "NAVL1_DAMPING", "Lateral guidance damping"),
    _same("FW_T_ALT_TC", "TECS_TIME_CONST", "Height error to climb rate time constant", "s"),
    _same("FW_T_TAS_TC", "TECS_SPD_TC", "Speed error to acceleration time constant", "s"),
    _same("FW_T_CLMB_MAX", "TECS_CLMB_MAX", "Climb rate at full throttle", "m/s"),
    _same("FW_T_SINK_MIN", "TECS_SINK_MAX", "Sink rate at idle (also the steepest descent "
          "demanded)", "m/s"),
    _same("FW_T_THR_DAMPING", "TECS_THR_DAMP", "Throttle damping of the energy-rate error",
          scale=4.0),
    _same("FW_T_THR_INTEG", "TECS_INTEG_GAIN", "Throttle integrator gain"),
    _same("FW_T_I_GAIN_PIT", "TECS_INTEG_GAIN", "Pitch integrator gain (the one integrator "
          "gain of both loops)", scale=3.0),
    _same("FW_T_PTCH_DAMP", "TECS_PTCH_DAMP", "Pitch damping of the balance-rate error"),
    _same("FW_T_SPDWEIGHT", "TECS_SPDWEIGHT", "Pitch looks after height (0), both (1), speed "
          "(2)"),
)  # fmt: skip


def _no_such_term(name: str, what: str) -> ParamDecl:
    return ParamDecl.fixed(name, 0.0, f"{what}: the controller has no such term, so it is "
                           "0 and cannot be changed")  # fmt: skip


ABSENT_TERMS = (
    _no_such_term("FW_RR_D", "Roll rate derivative gain"),
    _no_such_term("FW_RR_FF", "Roll rate feed-forward"),
    _no_such_term("FW_PR_D", "Pitch rate derivative gain"),
    _no_such_term("FW_PR_FF", "Pitch rate feed-forward"),
    _no_such_term("FW_YR_D", "Yaw rate derivative gain"),
    _no_such_term("FW_YR_I", "Yaw rate integrator gain"),
    _no_such_term("FW_YR_FF", "Yaw rate feed-forward"),
    _no_such_term("FW_RLL_TO_YAW_FF", "Roll to yaw feed-forward (aileron-rudder mixing)"),
)
TUNING_ALIASES = (*RATE_ALIASES, *LIMIT_ALIASES, *GUIDANCE_ALIASES, *ABSENT_TERMS)
