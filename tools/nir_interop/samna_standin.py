"""A stand-in for `samna` (SynSense's board driver, needed only for a real board): Rockpool 3.1
imports it unconditionally through its Xylo Audio 3 module. Every name is a stand-in."""
import importlib.abc, importlib.machinery, sys, types


class _Any(types.ModuleType):
    __path__ = []

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return _module(f"{self.__name__}.{name}")

    def __call__(self, *a, **k):
        return self

    def __mro_entries__(self, bases):
        return (object,)


def _module(name):
    if name not in sys.modules:
        sys.modules[name] = _Any(name)
    return sys.modules[name]


class _Finder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    def find_spec(self, name, path, target=None):
        if name == "samna" or name.startswith("samna."):
            return importlib.machinery.ModuleSpec(name, self, is_package=True)
        return None

    def create_module(self, spec):
        return _Any(spec.name)

    def exec_module(self, module):
        module.__path__ = []


sys.meta_path.insert(0, _Finder())
