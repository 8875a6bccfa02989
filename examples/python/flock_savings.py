"""Notebook-style example: annotated footage → formation parameters → a flock of 30 birds →
each bird's energy saving, plotted with matplotlib, and a tidy CSV for R.

    python examples/python/flock_savings.py [ANNOTATIONS] [--out DIR] [--seed N]

ANNOTATIONS defaults to the bundled barnacle geese V (examples_data/barnacle_geese_v.json);
any input format `formation extract` reads works. Writes into DIR (default: out/python):
  savings.png        mean saving per bird in the steady flight, with its range over time
  savings_tidy.csv   one row per frame and bird (the CSV columns; `read.csv()` in R)
  savings_per_bird.csv   one row per bird: mean, min and max saving in the steady flight
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import formation  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("annotations", nargs="?", default=ROOT / "examples_data" / "barnacle_geese_v.json")
parser.add_argument("--out", type=Path, default=Path("out/python"))
parser.add_argument("--seed", type=int, default=1)
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

# 1. Annotations → formation parameters (RANSAC over every annotated frame).
annotations = formation.read_annotations(args.annotations)
params = formation.extract(annotations, seed=args.seed)
print(f"{annotations.source}: {len(annotations)} frames, {params.birds} birds annotated")

# 2. Parameters → 30 birds: take-off, then 30 s of steady flight.
anim = formation.animate(params, birds=30, seconds=30, seed=args.seed)
name, start, end = next(s for s in anim.stages if s[0] == "steady")
print(f"{anim!r}; steady flight frames {start}..{end}")

# 3. Savings per bird in the steady flight: e is the saving of Hummel's model (the CSV's `e`
#    column, the fraction of a bird's solo induced power the others save it up to the model's
#    constant C, so values above 1 occur in large flocks; docs/model.md).
e = anim.savings[start:end]  # (frames, birds)
mean, low, high = e.mean(axis=0), e.min(axis=0), e.max(axis=0)
# Order the birds left to right across the formation (lateral offset from the leader).
table = anim.to_pandas()
steady = table[table["stage"] == "steady"]
lateral = steady.groupby("bird")["lateral"].mean().to_numpy()
order = np.argsort(lateral)

fig, ax = plt.subplots(figsize=(9, 4.5), dpi=120)
x = np.arange(anim.birds)
ax.bar(x, mean[order], color="#4c72b0", label="mean over the steady flight")
ax.errorbar(x, mean[order], yerr=np.vstack([mean - low, high - mean])[:, order],
            fmt="none", ecolor="#333333", capsize=2, label="range over time")
ax.set_xticks(x, [str(b) for b in order], fontsize=7)
ax.set_xlabel("bird (left to right across the formation)")
ax.set_ylabel("saving e (Hummel, without the constant C)")
ax.set_title(f"{anim.birds} birds from {Path(str(annotations.path)).name}: "
             f"mean saving e {mean.mean():.3f} per bird")
ax.legend(loc="upper right", fontsize=8)
ax.grid(axis="y", alpha=0.3)
fig.tight_layout()
fig.savefig(args.out / "savings.png")

# 4. Tidy CSVs for R: every frame and bird, and one row per bird.
table.to_csv(args.out / "savings_tidy.csv", index=False)
per_bird = steady.groupby("bird").agg(lateral=("lateral", "mean"), behind=("behind", "mean"),
                                      e_mean=("e", "mean"), e_min=("e", "min"), e_max=("e", "max"))
per_bird.to_csv(args.out / "savings_per_bird.csv")
assert np.allclose(per_bird["e_mean"].to_numpy(), mean)
print(f"wrote {args.out / 'savings.png'}, {args.out / 'savings_tidy.csv'} ({len(table)} rows), "
      f"{args.out / 'savings_per_bird.csv'}")
