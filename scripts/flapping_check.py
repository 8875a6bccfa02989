#!/usr/bin/env python3
"""Flapping check of the savings model: how much of a rigid wake's saving survives when the
wings flap.

Runs Ptera Software (`pip install pterasoftware==5.1.0`, MIT licence) on goose-like wings in
2- and 3-bird formations at the field's offsets, once with rigid wings (its steady ring
vortex-lattice solver: gliding, a steady wake) and once flapping (its unsteady ring vortex-lattice
method, UVLM), and writes each bird's saving to tests/data/flapping_check.json with the settings
and the package version. `tests/flapping_check.rs` compares it with the tool's own models at the
same offsets; docs/model.md has the table and what it does and does not show.

Usage: python3 scripts/flapping_check.py [OUT.json] [--fine]

Not run by CI (it needs pterasoftware and a few minutes of CPU); its stored output is checked.
--fine adds a finer mesh with one more wingbeat at the wild V's offset (about ten times the CPU).

What is computed. Every bird is the same wing: span b = 1.38 m, area 0.224 m^2 (a barnacle
goose), three cross sections (chords 0.20, 0.18, 0.07 m at 0, 0.40, 0.69 m from the root), a
NACA 0012 section, 5 degrees incidence, 18 m/s. Flapping is a dihedral oscillation at 4 Hz (the
species' wingbeat): the mid and tip cross sections move up and down in phase, the tip by
0.69 sin(15 deg) m, an amplitude at which the lone wing's mean thrust (about 0.86 N) about
balances the profile and parasite drag of the tool's power curve for this bird at 18 m/s
(13.5 W / 18 m/s = 0.75 N). Each follower flaps in *spatial* phase with the bird ahead (its
phase lags by 360 f dy / U degrees, dy its distance behind in metres: the wingtip follows the
leader's wingtip path, as Portugal et al. 2014 measured in ibises).

The saving is the follower's cycle-averaged inviscid mechanical power P = sum over panels of
F . (V_inf + v_apparent) (for a rigid wing P = D U, its induced power; for a flapping wing the
energy it leaves in the wake, thrust-producing losses included) against the same wing alone, at
equal lift: P is scaled by (L_alone / L)^2 (induced power at a given speed goes as lift
squared), so saving = 1 - P (L_alone / L)^2 / P_alone, a fraction of the wing's own inviscid
power like the tool's e.
"""
import json
import math
import sys
import time
from importlib.metadata import version

import numpy as np
import pterasoftware as ps
from pterasoftware import _functions

SPAN_M = 1.38
SPEED_MS = 18.0
WINGBEAT_HZ = 4.0
INCIDENCE_DEG = 5.0
FLAP_DEG = 15.0
SECTIONS = [(0.0, 0.20), (0.40, 0.18), (0.69, 0.07)]  # (distance from root m, chord m)

COARSE = {"chordwise": 3, "spanwise": (4, 3), "cycles": 3}
FINE = {"chordwise": 4, "spanwise": (6, 4), "cycles": 4}

# Offsets of each follower from the bird ahead, in wingspans: lateral between body centres,
# behind, above. Each with where it comes from. Every follower flies RISE above the bird ahead:
# level, the part of its wing that overlaps the leader's span would cut through the leader's
# wake sheet, which a vortex-lattice wake cannot represent (the panels would sit on wake
# filaments).
RISE = 0.06  # the filmed geese's median height difference between neighbours, wingspans
OFFSETS = [
    ("wild V, median nearest bird ahead (white-fronted geese)", 0.77, 1.24, RISE),
    ("northern bald ibis, about 1 m aside and 1 m behind (Portugal et al. 2014; span 1.3 m)", 0.77, 0.77, RISE),
    ("godwit simple V, modal neighbour (Corcoran & Hedrick 2019)", 0.8, 0.5, RISE),
    ("greylag geese, WTS +0.30 m (Speakman & Banks 1998, midpoint of range)", 1.2, 1.24, RISE),
    ("Hummel's optimum aside (pi/4), half a flapping wavelength behind", math.pi / 4, 0.5 * SPEED_MS / WINGBEAT_HZ / SPAN_M, RISE),
]


def wing(mesh, flapping):
    """One bird's wing (symmetric) and, when flapping, its movement."""
    sections = []
    for k, (yk, chord) in enumerate(SECTIONS):
        last = k == len(SECTIONS) - 1
        dy = yk - SECTIONS[k - 1][0] if k else 0.0
        sections.append(
            ps.geometry.wing_cross_section.WingCrossSection(
                airfoil=ps.geometry.airfoil.Airfoil(name="naca0012"),
                num_spanwise_panels=None if last else mesh["spanwise"][k],
                chord=chord,
                Lp_Wcsp_Lpp=(0.0, dy, 0.0),
                spanwise_spacing=None if last else "uniform",
                control_surface_symmetry_type="symmetric",
            )
        )
    w = ps.geometry.wing.Wing(
        wing_cross_sections=sections,
        symmetric=True,
        symmetryNormal_G=(0.0, 1.0, 0.0),
        symmetryPoint_G_Cg=(0.0, 0.0, 0.0),
        num_chordwise_panels=mesh["chordwise"],
        chordwise_spacing="uniform",
    )
    return w


def airplane(mesh, name, at):
    return ps.geometry.airplane.Airplane(
        wings=[wing(mesh, True)], name=name, Cg_GP1_CgP1=tuple(float(v) for v in at)
    )


def movement_of(plane, phase_deg, flapping):
    wms = [wing_movement_of(w, phase_deg, flapping) for w in plane.wings]
    return ps.movements.airplane_movement.AirplaneMovement(base_airplane=plane, wing_movements=wms)


def wing_movement_of(w, phase_deg, flapping):
    """The wing's movement (each half of a symmetric wing is a wing of its own)."""
    period = 1.0 / WINGBEAT_HZ
    csms = []
    for k, cs in enumerate(w.wing_cross_sections):
        dy = SECTIONS[k][0] - SECTIONS[k - 1][0] if k else 0.0
        amp = dy * math.sin(math.radians(FLAP_DEG)) if (flapping and k) else 0.0
        csms.append(
            ps.movements.wing_cross_section_movement.WingCrossSectionMovement(
                base_wing_cross_section=cs,
                ampLp_Wcsp_Lpp=(0.0, 0.0, amp),
                periodLp_Wcsp_Lpp=(0.0, 0.0, period if amp else 0.0),
                phaseLp_Wcsp_Lpp=(0.0, 0.0, phase_deg if amp else 0.0),
            )
        )
    return ps.movements.wing_movement.WingMovement(base_wing=w, wing_cross_section_movements=csms)


# Per-step power and forces of every airplane, recorded from the solver's load hook.
RECORD = []
_process = _functions.process_solver_loads


def _recording(solver, forces_GP1, moments):
    _process(solver, forces_GP1, moments)
    if hasattr(solver, "_currentVInf_GP1__E"):
        v_inf = solver._currentVInf_GP1__E
        w = v_inf + solver._calculate_current_movement_velocities_at_collocation_points()
    else:  # the steady solver: no movement
        v_inf = solver.vInf_GP1__E
        w = np.broadcast_to(v_inf, forces_GP1.shape)
    per = np.einsum("ij,ij->i", forces_GP1, w)
    out, start = [], 0
    for plane in getattr(solver, "current_airplanes", None) or solver.airplanes:
        n = sum(np.size(wg.panels) for wg in plane.wings)
        f = forces_GP1[start : start + n].sum(axis=0)
        u = v_inf / np.linalg.norm(v_inf)
        drag = float(f @ u)
        up = np.cross(u, np.array([0.0, 1.0, 0.0]))
        up = up if up[2] > 0 else -up
        out.append((float(per[start : start + n].sum()), drag, float(f @ up)))
        start += n
    RECORD.append(out)


_functions.process_solver_loads = _recording


def phase_lag_deg(behind_spans):
    """Spatial phase lock: the follower's wingbeat lags by 360 f dy / U."""
    lag = 360.0 * WINGBEAT_HZ * behind_spans * SPAN_M / SPEED_MS
    return -(lag % 360.0)


def run(positions, mesh, flapping, phase_mode="spatial"):
    """Cycle-averaged (power, drag, lift) of each bird; `positions` in wingspans (lateral,
    behind, above), the first the leader at the origin."""
    RECORD.clear()
    movements, ops = [], []
    for i, (x, y, z) in enumerate(positions):
        # Behind along the free stream (the wake's direction), above perpendicular to it.
        a = math.radians(INCIDENCE_DEG)
        at = (
            (y * math.cos(a) - z * math.sin(a)) * SPAN_M,
            x * SPAN_M,
            (y * math.sin(a) + z * math.cos(a)) * SPAN_M,
        )
        plane = airplane(mesh, f"bird {i}", at)
        if phase_mode == "spatial":
            phase = phase_lag_deg(y)
        else:
            phase = 0.0
        if phase <= -180.0:
            phase += 360.0
        movements.append(movement_of(plane, phase, flapping))
    op = ps.operating_point.OperatingPoint(rho=1.225, vCg__E=SPEED_MS, alpha=INCIDENCE_DEG)
    opm = ps.movements.operating_point_movement.OperatingPointMovement(base_operating_point=op)
    if not flapping:
        # Rigid wings: the steady ring vortex-lattice solver (each wake a steady sheet running
        # straight downstream to infinity), the limit the unsteady solver approaches.
        problem = ps.problems.SteadyProblem(airplanes=[m.base_airplane for m in movements], operating_point=op)
        solver = ps.steady_ring_vortex_lattice_method.SteadyRingVortexLatticeMethodSolver(problem)
        solver.run(calculate_streamlines=False)
        return np.array(RECORD[-1]).tolist(), 0.0, 1
    mv = ps.movements.movement.Movement(
        airplane_movements=movements, operating_point_movement=opm, num_cycles=mesh["cycles"]
    )
    problem = ps.problems.UnsteadyProblem(movement=mv, only_final_results=False)
    solver = ps.unsteady_ring_vortex_lattice_method.UnsteadyRingVortexLatticeMethodSolver(problem)
    solver.run(prescribed_wake=True, show_progress=False)
    dt = solver.delta_time
    n = int(round(1.0 / WINGBEAT_HZ / dt))
    last = np.array(RECORD[-n:])  # steps x birds x (P, drag, lift)
    return last.mean(axis=0).tolist(), float(dt), len(RECORD)


def saving(bird, alone):
    p, _, lift = bird
    p0, _, l0 = alone
    return 1.0 - p * (l0 / lift) ** 2 / p0


def case(name, offsets, mesh, flapping, alone, phase_mode="spatial"):
    pos = [(0.0, 0.0, 0.0)]
    for dx, dy, dz in offsets:
        px, py, pz = pos[-1]
        pos.append((px + dx, py + dy, pz + dz))
    t = time.process_time()
    birds, dt, steps = run(pos, mesh, flapping, phase_mode)
    return {
        "positions": pos,
        "birds": [
            {
                "power_w": b[0],
                "drag_n": b[1],
                "lift_n": b[2],
                "saving": saving(b, alone),
                "saved_w": alone[0] - b[0] * (alone[2] / b[2]) ** 2,
                "saving_same_incidence": 1.0 - b[0] / alone[0],
            }
            for b in birds
        ],
        "delta_time_s": dt,
        "steps": steps,
        "cpu_s": round(time.process_time() - t, 1),
    }


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    out = args[0] if args else "tests/data/flapping_check.json"
    mesh = COARSE
    result = {
        "what": "follower savings (fraction of inviscid power at equal lift) from Ptera Software's UVLM, rigid and flapping wings",
        "script": "scripts/flapping_check.py",
        "package": "pterasoftware",
        "package_version": version("pterasoftware"),
        "package_licence": "MIT",
        "settings": {
            "span_m": SPAN_M,
            "speed_ms": SPEED_MS,
            "wingbeat_hz": WINGBEAT_HZ,
            "incidence_deg": INCIDENCE_DEG,
            "flap_amplitude_deg": FLAP_DEG,
            "sections_m": SECTIONS,
            "mesh": mesh,
            "phase": "spatial phase lock (lag 360 f dy / U)",
            "saving": "1 - P (L_alone/L)^2 / P_alone, P = cycle mean of sum F.(V_inf + v_apparent)",
        },
        "cases": [],
    }
    alone = {}
    for flapping in (False, True):
        birds, dt, steps = run([(0.0, 0.0, 0.0)], mesh, flapping)
        alone[flapping] = birds[0]
        result["alone_" + ("flapping" if flapping else "rigid")] = {
            "power_w": birds[0][0], "drag_n": birds[0][1], "lift_n": birds[0][2], "delta_time_s": dt, "steps": steps
        }
        print("alone", "flapping" if flapping else "rigid", birds[0], flush=True)
    for name, dx, dy, dz in OFFSETS:
        for n_birds in (2, 3) if name.startswith("wild V") or name.startswith("northern") else (2,):
            c = {"offset": name, "lateral": dx, "behind": dy, "above": dz, "birds": n_birds}
            for flapping in (False, True):
                r = case(name, [(dx, dy, dz)] * (n_birds - 1), mesh, flapping, alone[flapping])
                c["flapping" if flapping else "rigid"] = r
            c["ratio"] = c["flapping"]["birds"][-1]["saving"] / c["rigid"]["birds"][-1]["saving"]
            c["ratio_watts"] = c["flapping"]["birds"][-1]["saved_w"] / c["rigid"]["birds"][-1]["saved_w"]
            print(name, n_birds, "rigid", round(c["rigid"]["birds"][-1]["saving"], 4), "flapping", round(c["flapping"]["birds"][-1]["saving"], 4), "ratio", round(c["ratio"], 3), flush=True)
            result["cases"].append(c)
    # Sensitivity to the follower's phase: in phase in time (no lag) at the wild V's offset.
    name, dx, dy, dz = OFFSETS[0]
    r = case(name, [(dx, dy, dz)], mesh, True, alone[True], phase_mode="synchronous")
    result["synchronous_wild_v"] = {"saving": r["birds"][-1]["saving"], "cpu_s": r["cpu_s"]}
    print("synchronous", r["birds"][-1]["saving"], flush=True)
    # Sensitivity to the discretisation: a finer mesh and one more cycle at the wild V's offset
    # (with --fine: about ten times the CPU of a coarse pair).
    sens = {"mesh": FINE}
    if "--fine" in sys.argv:
        fine_alone = {fl: run([(0.0, 0.0, 0.0)], FINE, fl)[0][0] for fl in (False, True)}
        for fl in (False, True):
            r = case(name, [(dx, dy, dz)], FINE, fl, fine_alone[fl])
            sens["flapping" if fl else "rigid"] = r["birds"][-1]["saving"]
        sens["ratio"] = sens["flapping"] / sens["rigid"]
        result["fine_wild_v"] = sens
        print("fine", sens, flush=True)
    # Sensitivity to the number of wingbeats: two instead of three, the wild V's pair.
    two = dict(mesh, cycles=2)
    two_alone = run([(0.0, 0.0, 0.0)], two, True)[0][0]
    r = case(name, [(dx, dy, dz)], two, True, two_alone)
    result["two_wingbeats_wild_v"] = {"flapping": r["birds"][-1]["saving"]}
    print("two wingbeats", r["birds"][-1]["saving"], flush=True)
    ratios = [c["ratio"] for c in result["cases"] if c["birds"] == 2]
    result["ratio_median"] = float(np.median(ratios))
    result["ratio_range"] = [float(min(ratios)), float(max(ratios))]
    with open(out, "w") as f:
        json.dump(result, f, indent=1)
        f.write("\n")
    print("wrote", out, "median ratio", result["ratio_median"])


if __name__ == "__main__":
    main()
