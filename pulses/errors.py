"""The one exception the readers raise for a record that cannot be used."""


class UnitsWarning(UserWarning):
    """Samples whose peak no accelerogram has in the units given (:class:`pulses.Record`).

    Examples
    --------
    >>> import warnings, numpy as np, pulses
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     rec = pulses.Record(0.874 * np.sin(np.arange(100) / 7.0), 0.01, units="nm/s2")
    >>> caught[0].category.__name__
    'UnitsWarning'
    """


class RecordError(ValueError):
    """A record file that cannot be read as an accelerogram.

    The message is one line that says what is wrong and, where the user can fix it, what to
    pass (for example ``units="cm/s2"``).

    Examples
    --------
    >>> import pulses
    >>> try:
    ...     pulses.read_record("no-such-file.sac")
    ... except pulses.RecordError as exc:
    ...     print(exc)
    no-such-file.sac: no such file
    """
