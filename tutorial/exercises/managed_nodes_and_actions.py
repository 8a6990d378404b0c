"""Checks for the exercise of notebook 11 (managed nodes and actions).

Exercise 11.1, a managed node's states: ``after(state, transition)``, the
primary state a managed node is in once ``transition`` has succeeded from
primary state ``state`` (``"unconfigured"``, ``"inactive"``, ``"active"``,
``"finalized"``), or None when that state has no such transition.  The
transitions are named by their labels, as ``rtt-ros2 lifecycle set``
takes them: ``configure``, ``cleanup``, ``activate``, ``deactivate``,
``shutdown``.

The rules are ROS 2's managed-node design (``lifecycle_msgs``), written out
here once (:data:`_MACHINE`); the visible cases are the path a tank's
controller walks and a few refusals, the hidden ones every pair, and every
name of a few that are no state or no transition.
"""

from __future__ import annotations

from tutorial.exercises.grader import Case, CaseFailed, Result, grade, hidden_random

STATES = ("unconfigured", "inactive", "active", "finalized")
TRANSITIONS = ("configure", "cleanup", "activate", "deactivate", "shutdown")
# Names a learner's answer might take for a transition or a state: another case, a transition state's name
# (lifecycle_msgs' "configuring", "errorprocessing"), a callback's, rclcpp's "destroy", nothing.  Every one is
# asked in every grading, so no learner's seed lets a mistake about them through.
STRANGE_TRANSITIONS = ("Configure", "ACTIVATE", "error", "", "destroy", "on_activate")
STRANGE_STATES = ("Active", "configuring", "", "errorprocessing")
_MACHINE = {  # the statement's rules: (state, transition) -> the state after; every other pair: None
    ("unconfigured", "configure"): "inactive",
    ("unconfigured", "shutdown"): "finalized",
    ("inactive", "cleanup"): "unconfigured",
    ("inactive", "activate"): "active",
    ("inactive", "shutdown"): "finalized",
    ("active", "deactivate"): "inactive",
    ("active", "shutdown"): "finalized",
}


def check_after(func) -> Result:
    """Check ``func(state, transition) -> str | None``; see the module text.

    While grading, hidden cases ask every pair of a drawn group (every
    state with each transition, in a drawn order), and every name of
    :data:`STRANGE_TRANSITIONS` with every state, and of :data:`STRANGE_STATES`
    with every transition, in a drawn order.
    """

    # A failing line without a hint of its own gets its case's (grader.CaseFailed).
    def ask(call: str, state, transition) -> None:
        expected = _MACHINE.get((state, transition))
        got = func(state, transition)
        if got != expected:
            raise CaseFailed(f"{call} returned {got!r}, expected {expected!r}.")

    def case(state: str, transition: str, hint: str) -> Case:
        call = f"after({state!r}, {transition!r})"
        return Case(call, lambda: ask(call, state, transition), hint)

    def every_pair_of(rng, states: tuple, label: str) -> Case:
        pairs = [(s, t) for s in states for t in TRANSITIONS]
        rng.shuffle(pairs)
        hint = "each state has its own transitions; the others give None."
        return Case(label, lambda: [ask(label, s, t) for s, t in pairs], hint, True)

    def strangers(rng) -> Case:
        names = [(s, t) for s in STATES for t in STRANGE_TRANSITIONS]
        names += [(s, t) for s in STRANGE_STATES for t in TRANSITIONS]
        rng.shuffle(names)
        label = "a name that is no transition, or no primary state"
        hint = "a name that is not one of the statement's is no transition of any state: None."
        return Case(label, lambda: [ask(label, s, t) for s, t in names], hint, True)

    rng = hidden_random("11.1")
    hidden = (
        [
            every_pair_of(rng, ("unconfigured", "inactive"), "every transition from unconfigured and inactive"),
            every_pair_of(rng, ("active", "finalized"), "every transition from active and finalized"),
            strangers(rng),
        ]
        if rng
        else []
    )
    return grade(
        "Exercise 11.1, a managed node's states",
        [
            case("unconfigured", "configure", "configure reads the parameters and makes the subscriptions: inactive."),
            case("inactive", "activate", "activate lets it work: active."),
            case("active", "deactivate", "deactivate stops the work and keeps what configure made: inactive."),
            case("inactive", "cleanup", "cleanup undoes configure: unconfigured."),
            case("active", "shutdown", "shutdown is a transition of every state but finalized."),
            case("unconfigured", "activate", "a node must be configured before it is activated: None."),
            case("active", "cleanup", "cleanup is a transition of inactive only: deactivate first."),
            case("finalized", "configure", "finalized is the end: no transition leaves it."),
            *hidden,
        ],
    )
