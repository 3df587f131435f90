"""Import an FMU's Python runtime from one zip in its resources: ``resources/<runtime>.zip``
holds the hydrofmu runtime (package ``hydrofmu_rt_<hash>``) and pythonfmu's slave API, each
module's source and its bytecode for the build's Python, so a host unpacks one file instead
of ~75.  (The rest of pythonfmu, its FMU builder, is not needed to run an FMU: where a host
imports it, it comes from the host's own pythonfmu.)

The build copies this file's text into every FMU's slave script (``fmi/build.py``), which
runs it once per runtime and process: `install` reads the zip whole into memory and puts
a finder at the front of ``sys.meta_path`` that serves the runtime's modules (and
pythonfmu's, while pythonfmu is the copy it served) from memory.  Why not ``zipimport``
with the zip on ``sys.path``:

- hosts delete an instance's unpacked folder at ``fmi2FreeInstance`` (fmpy, libcosim), while
  modules of the same runtime stay loaded for other instances; a zipimport module's lazy
  imports would then read from a deleted file.  From memory, the first zip read serves the
  process for good;
- zipimport caches an archive's table of contents by path, and hosts unpack into reused
  paths (a temporary folder named again, a cache folder);
- no ``sys.path`` entry, so nothing else in the host imports from the FMU by accident.

Modules get ``__file__`` where they would sit unpacked (``resources/<runtime>/…``): the
runtime's compiled kernels ship there as files (a shared library loads only from a file).
Standard library only, and nothing at module level but definitions: this text runs inside
the slave script of hosts that have nothing but Python and numpy.
"""
import marshal
import os
import sys
from importlib.machinery import ModuleSpec
from importlib.util import MAGIC_NUMBER

PYTHONFMU = "pythonfmu"


def read_zip(path):
    """{member name: bytes} of the zip at ``path`` (stored or deflated members; each CRC checked).
    Not ``zipfile``: it imports ``threading``, and a first import of ``threading`` on a host's
    worker thread (libcosim steps FMUs on its own threads) hangs the interpreter at exit."""
    import binascii
    with open(path, "rb") as f:
        data = f.read()
    u16 = lambda at: int.from_bytes(data[at:at + 2], "little")  # noqa: E731
    u32 = lambda at: int.from_bytes(data[at:at + 4], "little")  # noqa: E731
    end = data.rfind(b"PK\x05\x06")
    if end < 0:
        raise ImportError(f"{path}: not a zip file")
    files, at = {}, u32(end + 16)
    for _ in range(u16(end + 10)):
        if data[at:at + 4] != b"PK\x01\x02":
            raise ImportError(f"{path}: damaged zip directory")
        method, crc, size = u16(at + 10), u32(at + 16), u32(at + 20)
        n, extra, comment, local = u16(at + 28), u16(at + 30), u16(at + 32), u32(at + 42)
        name = data[at + 46:at + 46 + n].decode("utf-8")
        start = local + 30 + u16(local + 26) + u16(local + 28)
        blob = data[start:start + size]
        if method == 8:
            import zlib
            blob = zlib.decompress(blob, -15)
        elif method != 0:
            raise ImportError(f"{path}: {name} is compressed with method {method} (stored or deflated only)")
        if binascii.crc32(blob) != crc:
            raise ImportError(f"{path}: {name} is damaged (CRC mismatch)")
        files[name] = blob
        at += 46 + n + extra + comment
    return files


def _copies(package):
    """Folders of ``package`` on sys.path (installed copies)."""
    return [os.path.join(p, package) for p in sys.path
            if isinstance(p, str) and os.path.isfile(os.path.join(p, package, "__init__.py"))]


class RuntimeZip:
    """Finder and loader of the packages ``tops`` held in a runtime zip's members ``files``;
    ``where``: the folder the modules' ``__file__`` names (as if unpacked there)."""

    def __init__(self, runtime, files, where):
        self.runtime, self.files, self.where = runtime, files, where
        self.tops = {name.split("/")[0] for name in files if "/" in name}

    def _serves(self, fullname):
        top = fullname.partition(".")[0]
        if top not in self.tops:
            return False
        if top == PYTHONFMU and top != fullname:   # pythonfmu's submodules: only of our copy
            spec = getattr(sys.modules.get(top), "__spec__", None)
            return spec is not None and spec.loader is self
        return True

    def find_spec(self, fullname, path=None, target=None):
        if not self._serves(fullname):
            return None
        rel = fullname.replace(".", "/")
        for stem, package in ((rel + "/__init__", True), (rel, False)):
            if stem + ".py" in self.files:
                spec = ModuleSpec(fullname, self, origin=os.path.join(self.where, stem + ".py"),
                                  is_package=package)
                spec.has_location = True   # __file__: where the module would sit unpacked
                if package:   # submodules: from this finder; pythonfmu's others (its builder) from a copy on disk
                    spec.submodule_search_locations = _copies(fullname) if fullname == PYTHONFMU else []
                return spec
        return None

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        exec(self.get_code(module.__spec__.name), module.__dict__)

    def _stem(self, fullname):
        rel = fullname.replace(".", "/")
        return rel + "/__init__" if rel + "/__init__.py" in self.files else rel

    def get_source(self, fullname):
        return self.files[self._stem(fullname) + ".py"].decode("utf-8")

    def get_code(self, fullname):
        """The module's bytecode from the zip when it is for this Python, else its compiled source."""
        stem = self._stem(fullname)
        folder, _, base = stem.rpartition("/")
        pyc = self.files.get(f"{folder}/__pycache__/{base}.{sys.implementation.cache_tag}.pyc")
        if pyc is not None and pyc[:4] == MAGIC_NUMBER:
            return marshal.loads(pyc[16:])
        return compile(self.files[stem + ".py"], os.path.join(self.where, stem + ".py"), "exec",
                       dont_inherit=True)

    def is_package(self, fullname):
        return self._stem(fullname).endswith("/__init__")


def install(runtime, path):
    """The finder of ``runtime`` (a runtime package's name) in ``sys.meta_path``, made from the
    zip at ``path`` and put first when the process has none yet.  An existing finder names
    ``path``'s folder from now on: a module imported again (a build dropped it) finds its
    compiled kernels in a folder that exists."""
    where = os.path.dirname(os.path.abspath(path))
    for finder in sys.meta_path:
        if isinstance(getattr(finder, "runtime", None), str) and finder.runtime == runtime:
            finder.where = where
            return finder
    finder = RuntimeZip(runtime, read_zip(path), where)
    sys.meta_path.insert(0, finder)
    return finder
