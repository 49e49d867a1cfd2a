"""JSBSim as the bridge uses it: one aircraft, its initial conditions, wind, the true state."""

from __future__ import annotations

import logging
import math
from dataclasses import replace

import jsbsim

from bridges.jsbsim.conditions import TURBULENCE, Home
from bridges.jsbsim.ground_wind import wind_share
from bridges.sensor_models.sensor_errors import body_from_ned
from bridges.sensor_models.true_state import TrueState

__all__ = ["TURBULENCE", "Flight", "Home"]

log = logging.getLogger(__name__)

FT = 0.3048  # metres per foot

KT = 0.514444
MILSPEC = 3  # atmosphere/turb-type: FGWinds::ttMilspec
IDLE_THROTTLE = 0.05
TURBULENCE_MIN_AGL_M = 5.0
DROP_HEIGHT_FT = 4.0  # above the resting height of the shipped airframes' gear
SETTLE_S = 3.0
# Faster than any airframe here can fly, or below the ground it hit: JSBSim's ground
# reactions blow up at a crash (a 50 m/s dive gave 6,000 m/s the next frame, then 10^16).
DIVERGED_SPEED_M_S = 1000.0
DIVERGED_BELOW_GROUND_M = 50.0
STANDARD_GRAVITY = 9.80665


class Flight:
    """One JSBSim aircraft stepping at a fixed rate."""

    def __init__(
        self,
        model: str,
        rate_hz: float,
        home: Home,
        airborne_agl_m: float | None = None,
        speed_m_s: float = 0.0,
        bank_deg: float = 0.0,
    ) -> None:
        self.fdm = jsbsim.FGFDMExec(None)
        self.fdm.set_debug_level(0)
        if not self.fdm.load_model(model):
            raise ValueError(f"JSBSim has no aircraft {model!r}")
        self.fdm.set_dt(1.0 / rate_hz)
        self.dt_s = 1.0 / rate_hz
        self.wreck: TrueState | None = None  # after a crash the model diverged at
        self._wheels: list[str] | None = None  # the gear units that are wheels
        self._sane: TrueState | None = None  # the last state stepped to, found physical
        self.home = home
        self.turbulence = False
        self.brake_channel = False  # until a brakes servo is heard, idle means brakes
        self.rest_agl_m = 0.0  # the reference point's height on the wheels (0: not known)
        self.wind_ned = (0.0, 0.0, 0.0)  # m/s, the direction it blows towards
        self.wind_share = 1.0  # of it the model feels now (ground_wind)
        self._initial_conditions(model, airborne_agl_m, speed_m_s)
        if airborne_agl_m and bank_deg:
            self._bank(bank_deg)

    def _initial_conditions(
        self, model: str, airborne_agl_m: float | None, speed_m_s: float
    ) -> None:
        f, h = self.fdm, self.home
        f["ic/lat-geod-deg"] = h.lat_deg
        f["ic/long-gc-deg"] = h.lon_deg
        f["ic/terrain-elevation-ft"] = h.ground_msl_m / FT
        f["ic/psi-true-deg"] = h.heading_deg
        f["ic/h-agl-ft"] = (airborne_agl_m or 0.0) / FT
        f["ic/vc-kts"] = speed_m_s / KT if airborne_agl_m else 0.0
        if not airborne_agl_m:
            self._rest_on_gear()
        elif not f.run_ic():
            raise RuntimeError("JSBSim refused the initial conditions")
        f["propulsion/set-running"] = -1  # engines running, as if started on the ground
        f["fcs/mixture-cmd-norm"] = 1.0
        if airborne_agl_m:
            try:
                f["simulation/do_simple_trim"] = 1  # steady level flight at the given speed
            except jsbsim.TrimFailureError:
                log.warning("%s cannot trim at %.1f m/s: starting untrimmed", model, speed_m_s)
        else:
            self.set_controls({"throttle": 0.0})

    def _bank(self, bank_deg: float) -> None:
        """Roll the trimmed aircraft into a bank: its controls stay trimmed for level flight,
        so it starts as a real one handed over in a turn, dropping its nose."""
        f = self.fdm
        alpha, theta = f["aero/alpha-deg"], f["attitude/theta-deg"]
        f["ic/phi-deg"], f["ic/theta-deg"], f["ic/alpha-deg"] = bank_deg, theta, alpha
        if not f.run_ic():
            raise RuntimeError("JSBSim refused the banked initial conditions")

    def _rest_on_gear(self) -> None:
        """Start at the height and pitch the aircraft rests at on its wheels.

        Placed with its centre of gravity on the ground, JSBSim's gear springs throw the
        aircraft up and it lands on its nose; dropped from a little height it settles. So
        it is dropped once, and started again where it came to rest, at time zero.
        """
        f = self.fdm
        f["ic/h-agl-ft"] = DROP_HEIGHT_FT
        if not f.run_ic():
            raise RuntimeError("JSBSim refused the initial conditions")
        for _ in range(round(SETTLE_S / f.get_delta_t())):
            f.run()
        rest_agl_ft, rest_pitch_deg = f["position/h-agl-ft"], f["attitude/theta-deg"]
        self.rest_agl_m = rest_agl_ft * FT
        h = self.home
        f["ic/lat-geod-deg"], f["ic/long-gc-deg"] = h.lat_deg, h.lon_deg
        f["ic/psi-true-deg"] = h.heading_deg
        f["ic/h-agl-ft"], f["ic/theta-deg"] = rest_agl_ft, rest_pitch_deg
        if not f.run_ic():
            raise RuntimeError("JSBSim refused the initial conditions")
        f.set_sim_time(0.0)

    def set_wind(self, north: float, east: float, down: float) -> None:
        """Steady wind, m/s, the direction it blows towards."""
        self.wind_ned = (north, east, down)
        self._feel_wind(1.0)

    def _feel_wind(self, share: float) -> None:
        """Give the model ``share`` of the wind (``ground_wind``: its aerodynamics fail in
        an airflow from the side or behind, which only a slow aircraft on its wheels meets)."""
        self.wind_share = share
        north, east, down = (share * w for w in self.wind_ned)
        self.fdm["atmosphere/wind-north-fps"] = north / FT
        self.fdm["atmosphere/wind-east-fps"] = east / FT
        self.fdm["atmosphere/wind-down-fps"] = down / FT

    def _ground_wind(self) -> None:
        share = 1.0
        if self.weight_on_wheels():
            f = self.fdm
            rotation = body_from_ned(
                f["attitude/phi-rad"], f["attitude/theta-rad"], f["attitude/psi-rad"]
            )
            ground = (
                f["velocities/v-north-fps"] * FT,
                f["velocities/v-east-fps"] * FT,
                f["velocities/v-down-fps"] * FT,
            )
            share = wind_share(rotation @ ground, rotation @ self.wind_ned)
        if share != self.wind_share:
            self._feel_wind(share)

    def set_turbulence(self, level: str, seed: int | None = None) -> None:
        """MIL-F-8785C turbulence: none, light, moderate or severe; ``seed`` picks the gust
        sequence (JSBSim's own, which seeds 0 and 1 also give, when None)."""
        severity, wind_kt = TURBULENCE[level]
        self.turbulence = severity > 0
        if seed is not None:
            self.fdm["atmosphere/randomseed"] = seed
        if severity == 0:
            self.fdm["atmosphere/turb-type"] = 0
            return
        self.fdm["atmosphere/turb-type"] = MILSPEC if self._above_ground() else 0
        self.fdm["atmosphere/turbulence/milspec/severity"] = severity
        self.fdm["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = wind_kt * KT / FT

    def set_controls(self, controls: dict[str, float]) -> None:
        """Normalised commands (stick convention: elevator + is nose up) onto JSBSim's FCS."""
        f = self.fdm
        for surface, value in controls.items():
            if surface == "aileron":
                f["fcs/aileron-cmd-norm"] = value
            elif surface == "elevator":
                f["fcs/elevator-cmd-norm"] = -value  # JSBSim: + is stick forward, nose down
            elif surface == "rudder":
                f["fcs/rudder-cmd-norm"] = -value  # JSBSim: + yaws left
            elif surface == "throttle":
                f["fcs/throttle-cmd-norm"] = value
                if not self.brake_channel:
                    # No brake servo: a pilot holds the brakes at idle.
                    brake = 1.0 if value < IDLE_THROTTLE else 0.0
                    f["fcs/left-brake-cmd-norm"] = f["fcs/right-brake-cmd-norm"] = brake
            elif surface == "brakes":
                self.brake_channel = True
                brake = min(1.0, max(0.0, value))
                f["fcs/left-brake-cmd-norm"] = f["fcs/right-brake-cmd-norm"] = brake
            elif surface == "flaps":
                f["fcs/flap-cmd-norm"] = max(0.0, value)

    def controls(self) -> dict[str, float]:
        """The commands JSBSim holds now, in the stick convention."""
        f = self.fdm
        return {
            "aileron": f["fcs/aileron-cmd-norm"],
            "elevator": -f["fcs/elevator-cmd-norm"],
            "rudder": -f["fcs/rudder-cmd-norm"],
            "throttle": f["fcs/throttle-cmd-norm"],
        }

    def weight_on_wheels(self) -> bool:
        """Whether a wheel carries weight now (a wreck lies on the ground)."""
        if self.wreck is not None:
            return True
        if self._wheels is None:
            self._wheels = _wheel_properties(self.fdm)
        return any(self.fdm[name] > 0.5 for name in self._wheels)

    def _above_ground(self) -> bool:
        return float(self.fdm["position/h-agl-ft"]) * FT > TURBULENCE_MIN_AGL_M

    def step(self) -> None:
        """Advance one frame; past a crash the flight model diverged at, the wreck lies
        still where the aircraft came down (the vehicle on it keeps running)."""
        if self.wreck is not None:
            self.wreck = replace(self.wreck, t_s=self.wreck.t_s + self.dt_s)
            return
        if self.turbulence:
            # JSBSim's MIL-F-8785C scale lengths shrink with height; on the runway they
            # give gusts that throw a parked Cub into the air and the model into NaNs.
            self.fdm["atmosphere/turb-type"] = MILSPEC if self._above_ground() else 0
        if any(self.wind_ned):
            self._ground_wind()
        self.fdm.run()
        s = self._model_state()
        if _physical(s):
            self._sane = s
            return
        last = self._sane or s
        log.error("the aircraft crashed at %.2f s and JSBSim's model diverged: the wreck lies "
                  "still where it came down", s.t_s)  # fmt: skip
        self.wreck = _at_rest(last, s.t_s)

    @property
    def t_s(self) -> float:
        """Simulation time, seconds."""
        if self.wreck is not None:
            return self.wreck.t_s
        return float(self.fdm["simulation/sim-time-sec"])

    def state(self) -> TrueState:
        """The true state now (the one ``step`` read and judged, not read again)."""
        if self.wreck is not None:
            return self.wreck
        return self._sane if self._sane is not None else self._model_state()

    def _model_state(self) -> TrueState:
        f = self.fdm
        mass = f["inertia/mass-slugs"]
        yaw = math.remainder(f["attitude/psi-rad"], math.tau)
        fx, fy, fz = (f[f"forces/fb{a}-total-lbs"] / mass * FT for a in "xyz")
        return TrueState(
            t_s=self.t_s,
            lat_deg=f["position/lat-geod-deg"],
            lon_deg=f["position/long-gc-deg"],
            alt_msl_m=f["position/h-sl-ft"] * FT,
            alt_agl_m=f["position/h-agl-ft"] * FT,
            roll=f["attitude/phi-rad"],
            pitch=f["attitude/theta-rad"],
            yaw=yaw,
            vn=f["velocities/v-north-fps"] * FT,
            ve=f["velocities/v-east-fps"] * FT,
            vd=f["velocities/v-down-fps"] * FT,
            p=f["velocities/p-rad_sec"],
            q=f["velocities/q-rad_sec"],
            r=f["velocities/r-rad_sec"],
            f_body=(fx, fy, fz),
            airspeed_m_s=f["velocities/vtrue-fps"] * FT,
        )


def _physical(s: TrueState) -> bool:
    values = (s.lat_deg, s.lon_deg, s.alt_msl_m, s.alt_agl_m, s.vn, s.ve, s.vd, s.roll, s.pitch)
    if not all(math.isfinite(v) for v in values):
        return False
    speed = math.sqrt(s.vn * s.vn + s.ve * s.ve + s.vd * s.vd)
    return speed < DIVERGED_SPEED_M_S and s.alt_agl_m > -DIVERGED_BELOW_GROUND_M


def _at_rest(s: TrueState, t_s: float) -> TrueState:
    """The aircraft of state ``s`` lying level and still on the ground below it."""
    ground = s.alt_msl_m - max(s.alt_agl_m, 0.0)
    return replace(
        s, t_s=t_s, alt_msl_m=ground, alt_agl_m=0.0, roll=0.0, pitch=0.0, vn=0.0, ve=0.0,
        vd=0.0, p=0.0, q=0.0, r=0.0, f_body=(0.0, 0.0, -STANDARD_GRAVITY), airspeed_m_s=0.0,
    )  # fmt: skip


def _wheel_properties(fdm: jsbsim.FGFDMExec) -> list[str]:
    """The WOW properties of the gear's wheels: JSBSim numbers the structural contact
    points among the gear units too, and those have none."""
    names = []
    for i in range(int(fdm["gear/num-units"])):
        try:
            fdm[f"gear/unit[{i}]/WOW"]
        except KeyError:
            continue
        names.append(f"gear/unit[{i}]/WOW")
    return names
