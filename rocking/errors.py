"""The exception the rocking API raises for input it cannot use."""


class RockingInputError(ValueError):
    """An argument the solver or a design function cannot use (a missing excitation, a negative
    frequency parameter, ...).  The message is one line saying what is wrong and what to pass."""
