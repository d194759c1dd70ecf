"""The one exception the readers raise for a record that cannot be used."""


class UnitsWarning(UserWarning):
    """Samples whose peak no accelerogram has in the units given (:class:`pulses.Record`)."""


class RecordError(ValueError):
    """A record file that cannot be read as an accelerogram.

    The message is one line that says what is wrong and, where the user can fix it, what to
    pass (for example ``units="cm/s2"``).
    """
