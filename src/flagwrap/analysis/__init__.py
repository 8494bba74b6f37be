"""Analysis of run files: events (buckling onset, waiting time) and final-state classes.

Analysis objects follow one pattern (STYLE.md habit 9): configure the criterion in the
constructor (all thresholds are parameters with documented defaults), ``compute(...)``
returns ``self``, results are properties that raise before ``compute`` has run, and
``plot(ax=None)`` draws what the criterion saw.

* :class:`~flagwrap.analysis.buckling.WaitingTime` -- switch time, baseline, buckled or not,
  waiting time ``t_c / T`` (main text, "Slow dynamics right above the onset"; SI Fig. S7).
* :class:`~flagwrap.analysis.buckling.FinalState` -- "stable" / "wrapping" / "folding"
  (main text Fig. 5 symbols).
* :class:`~flagwrap.analysis.buckling.BucklingAnalysis` -- both, plus the perversion onset
  and torque peak/plateau, on the arrays of a run.
* :func:`~flagwrap.analysis.runfile_attrs.analyze_run_file` -- the above on a run file,
  stored back as attributes (``flagwrap analyze``).
"""

from flagwrap.analysis.buckling import (
    STATES,
    BucklingAnalysis,
    FinalState,
    WaitingTime,
    find_switch,
)

__all__ = ["STATES", "BucklingAnalysis", "FinalState", "WaitingTime", "find_switch"]
