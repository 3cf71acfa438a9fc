"""A module imported on first use: ``import pdyn`` does not pay for NumPy until a function
that needs it runs (NumPy's own import is 100-400 ms, more than the rest of pdyn)."""

import importlib
from typing import Any


class LazyModule:
    """Stands for module ``name``; the first attribute access imports it."""

    __slots__ = ("_name", "_module")

    def __init__(self, name: str):
        self._name = name
        self._module = None

    def __getattr__(self, attr: str) -> Any:
        module = self._module
        if module is None:
            module = importlib.import_module(self._name)
            self._module = module
        return getattr(module, attr)

    def __repr__(self) -> str:
        return f"<lazy module {self._name!r}>"
