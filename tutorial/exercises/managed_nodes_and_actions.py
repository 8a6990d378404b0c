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
controller walks and a few refusals, the hidden ones every pair and random
walks.
"""

from __future__ import annotations

from tutorial.exercises.grader import Case, CaseFailed, Result, grade, hidden_random

STATES = ("unconfigured", "inactive", "active", "finalized")
TRANSITIONS = ("configure", "cleanup", "activate", "deactivate", "shutdown")
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
    state with each transition, in a drawn order), walk the machine along
    drawn transitions, and give names that are no state or no transition.
    """

    def ask(call: str, state, transition, hint: str) -> None:
        expected = _MACHINE.get((state, transition))
        got = func(state, transition)
        if got != expected:
            raise CaseFailed(f"{call} returned {got!r}, expected {expected!r}.", hint)

    def case(state: str, transition: str, hint: str) -> Case:
        call = f"after({state!r}, {transition!r})"
        return Case(call, lambda: ask(call, state, transition, hint), hint)

    def every_pair_of(rng, states: tuple, label: str) -> Case:
        pairs = [(s, t) for s in states for t in TRANSITIONS]
        rng.shuffle(pairs)
        hint = "each state has its own transitions; the others give None."
        return Case(label, lambda: [ask(label, s, t, hint) for s, t in pairs], hint, True)

    def walk(rng) -> Case:
        steps = [rng.choice(TRANSITIONS) for _ in range(rng.randrange(8, 16))]
        label = "a walk along drawn transitions from unconfigured, each refused one skipped"
        hint = "the state after a transition is where the next one starts."

        def run():
            state = "unconfigured"
            for t in steps:
                ask(label, state, t, hint)
                state = _MACHINE.get((state, t), state)

        return Case(label, run, hint, True)

    def strangers(rng) -> Case:
        names = [
            (rng.choice(STATES), rng.choice(("Configure", "ACTIVATE", "error", "", "destroy", "on_activate"))),
            (rng.choice(("Active", "configuring", "", "errorprocessing")), rng.choice(TRANSITIONS)),
        ]
        label = "a name that is no transition, or no primary state"
        hint = "a name that is not one of the statement's is no transition of any state: None."
        return Case(label, lambda: [ask(label, s, t, hint) for s, t in names], hint, True)

    rng = hidden_random("11.1")
    hidden = (
        [
            every_pair_of(rng, ("unconfigured", "inactive"), "every transition from unconfigured and inactive"),
            every_pair_of(rng, ("active", "finalized"), "every transition from active and finalized"),
            walk(rng),
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
