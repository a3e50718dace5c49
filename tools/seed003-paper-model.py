#!/usr/bin/env python3
"""The timing-faults paper's loop as its listings describe it, outside ncpar, one ingredient
switched at a time, to show which of them sets the contour error it reports
(Table 5: 2.93 mm without misses, 11.05 mm with one miss in 500 periods).

Per axis (X, Y): the plant 250/(s(s+25)) stepped exactly under a zero-order
hold of T = 4 ms (c2d 'zoh'), a PID with kp 8.5, ki 0.38, kd 0.35, the circle
R = 1000 mm, 2 s, started at rest on its start point; contour error as Eq. (9)
(the radial distance of the midpoint of two successive actual positions).

Switches (one per row of the output):
  frames   shared: one frame carries both axes' setpoints (ncpar's default);
           per-axis: each servo node has its own frame (the paper's Fig. 5)
  miss     what a missed period does: sp = the servo holds its last setpoint
           (ncpar's MISS_POLICY = hold); u = the actuator keeps its last output
           (the paper: "the actuator cannot get the control input"); freeze =
           the axis' discrete plant is not stepped that period (the listing
           simulates tf2ss(c2d(G)) inside the servo task)
  pid      cont: ki * integral e dt + kd * de/dt (ncpar's sim); sample:
           kd * (e - e_prev), the derivative per sample
  delay    sample-to-actuation latency in periods (0: as ncpar's sim)
  unit     mm or m: the PID on the error in metres (a linear loop: no change)

usage: seed003-paper-model.py      prints one line per variant:
  variant  clean_max clean_mean  worst_single_miss_max(1.36-1.64 s, X or Y)
"""
import math

T, K, P, R, W = 0.004, 250.0, 25.0, 1000.0, math.pi
N = 500


def evolve(x, v, u, dt):
    if dt <= 0:
        return x, v
    e = math.exp(-P * dt)
    vinf = K * u / P
    dv = v - vinf
    return x + vinf * dt + dv * (1 - e) / P, vinf + dv * e


def run(frames="shared", miss_sem="sp", pid="cont", delay=0.0, unit="mm", miss=None, axis=0):
    s = 1e-3 if unit == "m" else 1.0
    ref = lambda k: (R * math.cos(W * k * T), R * math.sin(W * k * T))
    nd = int(delay)
    frac = delay - nd
    st = [dict(x=ref(0)[a], v=0.0, I=0.0, ep=0.0, u=0.0, r=ref(0)[a], ys=[ref(0)[a]] * (nd + 1))
          for a in range(2)]
    pos = []
    for k in range(N + 1):
        pos.append((st[0]["x"], st[1]["x"]))
        r = ref(k)
        for a in range(2):
            q = st[a]
            q["ys"].append(q["x"])
            y = q["ys"][-1 - nd]
            lost = k == miss and (frames == "shared" or a == axis)
            if lost and miss_sem == "freeze":
                continue
            if lost and miss_sem == "u":
                u = q["u"]
            else:
                if not lost:
                    q["r"] = r[a]
                e = (q["r"] - y) * s
                q["I"] += e * T
                de = (e - q["ep"]) / (T if pid == "cont" else 1.0)
                u = 8.5 * e + 0.38 * q["I"] + 0.35 * de
                q["ep"] = e
                u /= s
            q["x"], q["v"] = evolve(q["x"], q["v"], q["u"], frac * T)
            q["x"], q["v"] = evolve(q["x"], q["v"], u, T - frac * T)
            q["u"] = u
    return [abs(R - math.hypot((pos[i - 1][0] + pos[i][0]) / 2, (pos[i - 1][1] + pos[i][1]) / 2))
            for i in range(1, len(pos))]


def row(name, **kw):
    clean = run(**kw)
    worst = max(max(run(miss=m, axis=a, **kw)) for m in range(340, 411, 2) for a in (0, 1))
    print("%-44s %7.3f %7.3f %7.3f" % (name, max(clean), sum(clean) / len(clean), worst))


def main():
    print("%-44s %7s %7s %7s" % ("variant (paper: 2.93 clean, 11.05 one miss)", "max", "mean",
                                  "miss"))
    row("ncpar: shared frame, setpoint held")
    row("same, PID on the error in metres", unit="m")
    row("per-axis frames, setpoint held", frames="per-axis")
    row("per-axis frames, actuator keeps its output", frames="per-axis", miss_sem="u")
    row("per-axis frames, plant not stepped", frames="per-axis", miss_sem="freeze")
    row("per-axis, plant not stepped, 1 period late", frames="per-axis", miss_sem="freeze", delay=1)
    row("per-axis, plant not stepped, 2 periods late", frames="per-axis", miss_sem="freeze", delay=2)
    row("per-axis, setpoint held, 2.5 periods late", frames="per-axis", delay=2.5)
    row("per-axis, setpoint held, derivative per sample", frames="per-axis", pid="sample")


if __name__ == "__main__":
    main()
