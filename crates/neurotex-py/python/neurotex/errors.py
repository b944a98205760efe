"""Exceptions of neurotex. Every one is a :class:`Error`; most are also the builtin
exception a Python user expects (``ValueError``, ``FileNotFoundError``, ``OSError``), so
``except ValueError`` works as usual. Messages are the library's own, naming the file,
recording, line or parameter at fault."""


class Error(Exception):
    """Base class of every neurotex error."""


class ParameterError(Error, ValueError):
    """A parameter broke its rule (``levels`` of 1, a negative ``gain``, ...)."""


class DataError(Error, ValueError):
    """Bad input data: wrong shape, NaN or infinite samples, too short, bad manifest."""


class NotFoundError(Error, FileNotFoundError):
    """A file or dataset folder that does not exist."""


class ReadWriteError(Error, OSError):
    """A file that exists but cannot be read or written."""


class ModelError(Error, ValueError):
    """A model file that is not a neurotex model, of another version, damaged, or with
    content neurotex never writes."""


class ClassifyError(Error, ValueError):
    """Training or test data a classifier cannot use (k larger than the training set...)."""


class InternalError(Error):
    """A bug inside neurotex, caught before it could crash Python. Please report it."""


__all__ = [
    "Error",
    "ParameterError",
    "DataError",
    "NotFoundError",
    "ReadWriteError",
    "ModelError",
    "ClassifyError",
    "InternalError",
]
