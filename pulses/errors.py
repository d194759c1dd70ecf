"""The one exception the readers raise for a record that cannot be used."""


class RecordError(ValueError):
    """A record file that cannot be read as an accelerogram.

    The message is one line that says what is wrong and, where the user can fix it, what to
    pass (for example ``units="cm/s2"``).

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> import pulses
    >>> path = os.path.join(tempfile.mkdtemp(), "acc.txt")
    >>> np.savetxt(path, [0.0, 0.1, -0.2])
    >>> try:
    ...     pulses.read_record(path, dt=0.01)
    ... except pulses.RecordError as err:
    ...     print("units" in str(err))
    True
    """
