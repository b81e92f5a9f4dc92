"""A fact of the paper checked on a configuration: its named conditions, which of them hold, and why not.

Each condition says whose it is: ``ROTOR``, a number of the paper's rotor (a critical speed, a blade count, a chord
fraction, a closure in mm), which another configuration need not share (failing it is no defect of that
configuration); ``FINDING``, what the paper reports of the formulations (3D contains 2D, 2D diverges where 3D
settles), whose failure on a configuration is a result to look at. A failing fact's ``why`` names every failed
condition with our value and, for the rotor's numbers, says so.

>>> f = with_conditions({"id": 9}, [condition("three blades touch", False, "4", ROTOR), condition("x", True, "1")])
>>> f["holds"], f["why"].split(":")[0]
(False, 'three blades touch')
"""

from __future__ import annotations

ROTOR = "the paper's rotor"  # a number of the paper's rotor (a count, a speed, a fraction): another need not have it
FINDING = "the paper's finding"  # what the paper reports of the formulations: failing it here is a result


def condition(text: str, holds: bool, ours: str, kind: str = FINDING) -> dict:
    """One condition of a paper fact: what it says, whether it holds here, our value in words, and whose it is
    (ROTOR: a number of the paper's rotor, which another configuration need not share; FINDING: the paper's
    claim about the formulations)."""
    return {"condition": text, "holds": bool(holds), "ours": ours, "kind": kind}


def with_conditions(fact: dict, conds: list[dict]) -> dict:
    """``fact`` with its conditions, ``holds`` = all of them, and (where one fails) ``why``: each failed condition
    by name with our value, and whether it is the paper's rotor's number rather than a defect of the configuration."""
    fact["conditions"] = conds
    fact["holds"] = all(c["holds"] for c in conds)
    failed = [c for c in conds if not c["holds"]]
    if failed:
        fact["why"] = "; ".join(
            f"{c['condition']}: ours {c['ours']}" + (f" (a number of {ROTOR}: another configuration need not have it, "
                                                     "not a defect of this one)" if c["kind"] == ROTOR else "")
            for c in failed)
    return fact
