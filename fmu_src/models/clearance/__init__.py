"""TipClearance: the closure of a fan's tip clearance from the spool speed (native C)."""
