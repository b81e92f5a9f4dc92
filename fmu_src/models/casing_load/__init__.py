"""CasingLoad: the fan case's ovalization and rigid offset during a manoeuvre, from a load-factor schedule
(native C)."""
