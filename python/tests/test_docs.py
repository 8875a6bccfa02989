"""docs/python.md against the package: the first run's repr, stages and shape as the comments
give them, the progress callable's stage names, the options examples and the signature table.

Run from the repository root after installing the package: `python -m pytest python/tests`.
"""

import inspect
import re
from pathlib import Path

import formation

ROOT = Path(__file__).resolve().parents[2]
DOC = (ROOT / "docs" / "python.md").read_text()


def comment_after(code: str) -> str:
    """The `# ...` comment of the first-run line that starts with `code`."""
    m = re.search(rf"^{re.escape(code)}\s+# (.*)$", DOC, re.M)
    assert m, f"docs/python.md: no line {code!r} with a comment"
    return m.group(1).strip()


def test_the_first_run_is_as_documented():
    params = formation.extract(formation.example("barnacle_geese_v.json"), seed=1)
    anim = formation.animate(params, birds=30, seconds=30, seed=1)
    assert comment_after("anim") == repr(anim)
    assert comment_after("anim.stages") == repr(anim.stages)
    assert comment_after("anim.positions.shape") == repr(anim.positions.shape)


def test_the_progress_stage_names_are_the_documented_ones():
    params = formation.extract(formation.example("barnacle_geese_v.json"), seed=1)
    seen = set()
    for birds in (14, 30):
        formation.animate(params, birds=birds, seconds=1, seed=1, progress=lambda s, d, t: seen.add(s))
    section = DOC[DOC.index("## Threads and progress"):]
    section = " ".join(section[: section.index("```")].split())
    named = set(re.findall(r"`([a-z][a-z :-]*)`", section))
    assert seen <= named, f"stages reported but not documented: {sorted(seen - named)}"


def test_the_options_examples_run():
    params = formation.extract(formation.example("barnacle_geese_v.json"), seed=1)
    block = DOC[DOC.index("## Options"):]
    block = block[block.index("```python") + len("```python"): block.index("```", block.index("```python") + 9)]
    for line in filter(None, map(str.strip, block.splitlines())):
        # The documented call, one second of flight to keep it short.
        anim = eval(line.replace("birds=40,", "birds=40, seconds=1,"), {"formation": formation, "params": params})
        assert isinstance(anim, formation.Animation), line


def test_the_signature_table_has_every_keyword():
    row = next(line for line in DOC.splitlines() if line.startswith("| `formation.animate("))
    for name in inspect.signature(formation.animate).parameters:
        assert re.search(rf"\b{name}\b", row.split("|")[1]), f"the animate row lacks {name}"
