"""Exceptions raised by glint (the compiled module raises them too)."""

from typing import Optional


class SceneError(ValueError):
    """A scene that cannot be read, built or rendered.

    Attributes: ``message`` (the error alone), ``file`` (the file it is in, or None),
    ``line`` and ``col`` (1-based; 0 when unknown). ``str(err)`` is ``file:line:col:
    message``, as the command line prints it.
    """

    def __init__(self, text: str, message: str = "", file: Optional[str] = None, line: int = 0, col: int = 0):
        super().__init__(text)
        self.message = message or text
        self.file = file
        self.line = line
        self.col = col
