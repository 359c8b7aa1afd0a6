"""Read the normal modes of a Nastran OP2 file: real eigenvalues (LAMA) and real eigenvectors
(OUGV1 / BOUGV1 / OUG1) of a SOL 103 run, 32- or 64-bit words, little- or big-endian.

Sources for the layout: the MSC Nastran DMAP Programmer's Guide (OUTPUT2 / OP2 table format,
OFP table codes) and pyNastran's reader (``pyNastran/op2/op2_interface/op2_reader.py``,
``op2_common.py`` ``_set_approach_code``, ``tables/oug/oug.py`` and
``tables/lama_eigenvalues/lama.py``), which is the reference the tests compare against.

Layout (``[n]`` is a Fortran record holding the one word n; every Fortran record is
``<len> bytes <len>`` with 4-byte lengths; a word is 4 bytes, or 8 in a 64-bit OP2 (integers
int64, reals float64, characters 4 per word padded with 4 blanks, or 8 per word), the word size
and byte order known from the first record, one word 3 (POST -1) or 2 (POST -2)):

* optional header (``PARAM,POST,-1``): ``[3] date(3 words) [7] 'NASTRAN FORT TAPE ID CODE - '
  [2] label(8 chars) [-1] [0]``;
* each table: ``[2] name(8 chars) [-1] [7] trailer(7 words) [-2] [1] [0] [n] name-record
  [-3] [1] [0]``, then logical records each followed by ``[-k] [1] [0]`` (k = 4, 5, ...) and
  a closing ``[0]``. A logical record is ``[n] data(n words)`` possibly continued by more
  ``[n'] data`` pairs while the next one-word record is positive;
* in a results table the logical records alternate: the 146-word IDENT record (word 1 approach
  code = 10 analysis code + device code, word 2 table code (+1000 sort code), word 4 subcase,
  word 5 mode, word 6 eigenvalue, word 9 format code, word 10 words per entry, word 23
  thermal flag) and the data record;
* OUG data, SORT1 real (num_wide 8): per grid ``10 grid + device, grid type, T1 T2 T3 R1 R2 R3``
  (ints, then reals); real normal modes have analysis code 2 and table code 7
  (eigenvector; pyNastran's writer uses 1, displacement, which with analysis code 2 is the same
  mode shape and is accepted too);
* LAMA data: per mode ``mode, extraction order, eigenvalue [rad^2/s^2], omega [rad/s], f [Hz],
  generalised mass, generalised stiffness`` (2 ints, 5 floats).

Other tables are skipped by their Fortran record lengths only, so any content between is
accepted. The eigenvectors are in the frame of the table: BOUGV1 the basic frame (preferred
when present), OUGV1/OUG1 each grid's displacement (CD) frame. Bad or unsupported content
(complex or SORT2 eigenvectors, several subcases, a broken record structure)
raises :class:`taos.errors.InputError` naming the file.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from taos.errors import InputError

#: largest logical record read into memory [bytes] (256 MiB: 8 million grids of a 32-bit OP2)
MAX_RECORD_BYTES = 1 << 28
#: most modes taken from one file
MAX_MODES = 100_000
#: eigenvector tables, in order of preference (basic frame first)
EIGENVECTOR_TABLES = ("BOUGV1", "OUGV1", "OUG1")
IDENT_WORDS = 146


@dataclass(frozen=True)
class Op2Modes:
    """Real normal modes read from an OP2 file (the FE model's units)."""

    mode: np.ndarray                    # (n,) Nastran mode numbers
    eigenvalue_rad2_s2: np.ndarray      # (n,) lambda = omega^2 [rad^2/s^2]
    generalised_mass: np.ndarray | None  # (n,) from LAMA, None without a LAMA table
    generalised_stiffness: np.ndarray | None
    grids: np.ndarray                   # (G,) grid ids, ascending
    phi: np.ndarray                     # (n, G, 6) T1 T2 T3 R1 R2 R3
    table: str                          # the eigenvector table read
    endian: str                         # "<" or ">"
    word_bytes: int                     # 4 (32-bit OP2) or 8 (64-bit)

    @property
    def freq_hz(self) -> np.ndarray:
        return np.sqrt(np.maximum(self.eigenvalue_rad2_s2, 0.0)) / (2.0 * np.pi)


class _Reader:
    def __init__(self, f, src: str, size: int):
        self.f, self.src, self.size = f, src, size
        head = f.read(4)
        if len(head) < 4:
            raise InputError(src, "(file)", "a Nastran OP2 file", got="an empty or truncated file")
        le, be = struct.unpack("<i", head)[0], struct.unpack(">i", head)[0]
        if le not in (4, 8) and be not in (4, 8):
            raise InputError(src, "(file)", "a Nastran OP2 file (first Fortran record of one 4- or 8-byte word)",
                             got=f"first record length {le}")
        self.e = "<" if le in (4, 8) else ">"
        self.w = le if le in (4, 8) else be                  # bytes per word: 4 (32-bit) or 8 (64-bit)
        self.wfmt = self.e + ("i" if self.w == 4 else "q")
        f.seek(0)

    def bad(self, what: str, got: str):
        return InputError(self.src, f"byte {self.f.tell()}", what, got=got)

    def record(self, keep: int) -> tuple[int, bytes | None] | None:
        """Next Fortran record: (length, its bytes if length <= keep else None); None at the end."""
        h = self.f.read(4)
        if not h:
            return None
        if len(h) < 4:
            raise self.bad("a Fortran record length", "the file truncated")
        n = struct.unpack(self.e + "i", h)[0]
        if n < 0 or self.f.tell() + n + 4 > self.size:
            raise self.bad("a Fortran record within the file", f"length {n}")
        if n <= keep:
            data = self.f.read(n)
        else:
            data = None
            self.f.seek(n, 1)
        if struct.unpack(self.e + "i", self.f.read(4))[0] != n:
            raise self.bad("matching Fortran record lengths", "a mismatch (not an OP2 or a corrupt one)")
        return n, data

    def marker(self) -> int:
        r = self.record(self.w)
        if r is None or r[0] != self.w:
            raise self.bad("a one-word OP2 marker", "the end of the file" if r is None else f"{r[0]} bytes")
        return struct.unpack(self.wfmt, r[1])[0]

    def peek_marker(self) -> int | None:
        pos = self.f.tell()
        r = self.record(self.w)
        self.f.seek(pos)
        return None if r is None or r[0] != self.w else struct.unpack(self.wfmt, r[1])[0]

    def expect(self, *vals: int) -> None:
        for v in vals:
            m = self.marker()
            if m != v:
                raise self.bad(f"the OP2 marker {v}", str(m))

    def logical(self, keep: bool) -> bytes | None:
        """A logical record ``[n] data`` plus its continuations; its bytes if ``keep``."""
        parts, total = [], 0
        while True:
            n = self.marker()
            if n <= 0:
                raise self.bad("a record word count", str(n))
            total += self.w * n
            if keep and total > MAX_RECORD_BYTES:
                raise self.bad(f"records up to {MAX_RECORD_BYTES} bytes", f"{total} bytes")
            r = self.record(self.w * n if keep else 0)
            if r is None or r[0] != self.w * n:
                raise self.bad(f"a record of {n} words", "the end of the file" if r is None else f"{r[0]} bytes")
            if keep:
                parts.append(r[1])
            nxt = self.peek_marker()
            if nxt is None or nxt <= 0:
                return b"".join(parts) if keep else None

    def table(self, sink) -> None:
        """The body of a table whose name record was just read: its logical records after [-3],
        each passed to ``sink`` (None: skipped by their lengths)."""
        self.expect(-1)
        self.logical(False)
        self.expect(-2, 1, 0)
        self.logical(False)
        self.expect(-3, 1, 0)
        k = -3
        while self.peek_marker() != 0:
            rec = self.logical(sink is not None)
            if sink is not None:
                sink(rec)
            k -= 1
            self.expect(k, 1, 0)
        self.expect(0)


def _tables(path, src: str, wanted: set[str], sink) -> None:
    """Pass every logical record of the tables named in ``wanted`` to ``sink(name, record,
    endian, bytes per word)``, in file order; skip the others."""
    size = Path(path).stat().st_size
    with open(path, "rb") as f:
        rd = _Reader(f, src, size)
        prev: tuple[int, bytes | None] | None = None
        while True:
            r = rd.record(8 * rd.w)
            if r is None:
                break
            # a table starts with [2] name(8 chars) (or [8] name(32 chars)) then [-1] [7]
            if prev is not None and prev[0] == rd.w and r[0] in (2 * rd.w, 8 * rd.w) and r[1] is not None:
                nw = struct.unpack(rd.wfmt, prev[1])[0]
                pos = f.tell()
                if rd.w * nw == r[0] and rd.peek_marker() == -1:
                    rd.record(rd.w)
                    seven = rd.peek_marker()
                    f.seek(pos)
                    if seven == 7:
                        name = _name(r[1], rd.w)
                        if name in wanted:
                            rd.table(lambda rec, name=name: sink(name, rec, rd.e, rd.w))
                        else:
                            try:
                                rd.table(None)
                            except InputError:      # a table of another layout: go on record by record
                                f.seek(pos)
                        prev = None
                        continue
            prev = r


def _name(b: bytes, w: int) -> str:
    """A table name: 8 characters, or with 8-byte words either 16 characters or two words of 4
    characters and 4 blanks each."""
    if w == 8 and b[4:8] == b"    " and b[12:16] == b"    ":
        b = b[0:4] + b[8:12]
    return b[:8].decode("latin-1").strip()


def _ident(rec: bytes, e: str, nb: int) -> dict:
    w = np.frombuffer(rec, dtype=f"{e}i{nb}")
    fl = np.frombuffer(rec, dtype=f"{e}f{nb}")
    return {"approach": int(w[0]), "tcode": int(w[1]), "subcase": int(w[3]), "mode": int(w[4]),
            "eigenvalue": float(fl[5]), "num_wide": int(w[9]), "thermal": int(w[22])}


class _Collector:
    """Sink of :func:`_tables`: the LAMA records, and per eigenvector table its modes (only the
    grids asked for, when given)."""

    def __init__(self, src: str, grids):
        self.src = src
        self.want = None if grids is None else np.unique(np.asarray(list(grids), dtype=np.int64))
        self.lama: list[bytes] = []
        self.clama = False
        self.e, self.w = "<", 4
        self.pending: dict[str, dict | None] = {t: None for t in EIGENVECTOR_TABLES}
        self.modes: dict[str, dict[int, tuple[float, np.ndarray, np.ndarray]]] = {t: {} for t in EIGENVECTOR_TABLES}
        self.subcases: dict[str, set[int]] = {t: set() for t in EIGENVECTOR_TABLES}
        self.present: set[str] = set()

    def __call__(self, name: str, rec: bytes, e: str, nb: int) -> None:
        self.e, self.w = e, nb
        if name == "CLAMA":
            self.clama = True
            return
        if name == "LAMA":
            self.lama.append(rec)
            return
        self.present.add(name)
        idn = self.pending[name]
        if idn is None:                                  # an IDENT record
            if len(rec) != nb * IDENT_WORDS:
                raise InputError(self.src, f"{name} IDENT", f"{IDENT_WORDS} words", got=f"{len(rec) // nb}")
            self.pending[name] = _ident(rec, e, nb)
            return
        self.pending[name] = None                        # its data record
        acode, tcode, sort = idn["approach"] // 10, idn["tcode"] % 1000, idn["tcode"] // 1000
        if tcode not in (1, 7) or (tcode == 1 and acode not in (2, 9)):
            return                                       # not a mode shape (e.g. static displacements)
        if acode != 2 or idn["num_wide"] != 8 or sort & 2 or idn["thermal"]:
            kind = ("complex eigenvectors (SOL 107/110)" if acode == 9 or idn["num_wide"] != 8 else
                    "SORT2 eigenvectors" if sort & 2 else f"analysis code {acode}, thermal {idn['thermal']}")
            raise InputError(self.src, name, "real normal modes in SORT1 (SOL 103)", got=kind)
        if len(rec) % (8 * nb):
            raise InputError(self.src, f"{name} mode {idn['mode']}", "8 words per grid",
                             got=f"{len(rec) // nb} words")
        ids = np.frombuffer(rec, dtype=f"{e}i{nb}").reshape(-1, 8)[:, 0] // 10
        vals = np.frombuffer(rec, dtype=f"{e}f{nb}").reshape(-1, 8)[:, 2:8]
        if self.want is not None:
            keep = np.isin(ids, self.want)
            ids, vals = ids[keep], vals[keep]
        modes = self.modes[name]
        if idn["mode"] in modes:
            raise InputError(self.src, f"{name} mode {idn['mode']}", "each mode once (one subcase)", got="twice")
        if len(modes) >= MAX_MODES:
            raise InputError(self.src, name, f"at most {MAX_MODES} modes", got="more")
        modes[idn["mode"]] = (idn["eigenvalue"], ids.astype(np.int64), vals.astype(float))
        self.subcases[name].add(idn["subcase"])


def read_op2_modes(path, grids=None) -> Op2Modes:
    """Real normal modes of the OP2 file ``path`` (module docstring for the layout); with
    ``grids``, only those grids' components are kept (the others are read and dropped)."""
    src = str(path)
    c = _Collector(src, grids)
    try:
        _tables(path, src, set(EIGENVECTOR_TABLES) | {"LAMA", "CLAMA"}, c)
    except FileNotFoundError:
        raise InputError(src, "(file)", "an existing Nastran OP2 file", got="no such file") from None
    except IsADirectoryError:
        raise InputError(src, "(file)", "a Nastran OP2 file", got="a directory") from None
    except OSError as ex:
        raise InputError(src, "(file)", "a readable Nastran OP2 file", got=type(ex).__name__) from None
    e, nb = c.e, c.w
    name = next((t for t in EIGENVECTOR_TABLES if c.modes[t]), None)
    if name is None:
        if c.present:
            raise InputError(src, sorted(c.present)[0], "eigenvectors (table code 7, or 1 with analysis code 2)",
                             got="none")
        got = "complex eigenvalues (CLAMA) only" if c.clama else "none"
        raise InputError(src, "OUGV1", "a real eigenvector table (BOUGV1, OUGV1 or OUG1 of a SOL 103 run with "
                         "DISP = ALL)", got=got)
    if any(v is not None for v in c.pending.values()):
        raise InputError(src, name, "IDENT and data records in pairs", got="an IDENT record alone")
    if len(c.subcases[name]) > 1:
        raise InputError(src, name, "the modes of one subcase", got=f"subcases {sorted(c.subcases[name])}")
    modes = c.modes[name]
    order = sorted(modes)
    gids = modes[order[0]][1]
    if np.unique(gids).size != gids.size:
        raise InputError(src, name, "each grid once per mode", got="a grid repeated")
    srt = np.argsort(gids)
    phi = np.zeros((len(order), gids.size, 6))
    lam = np.zeros(len(order))
    for j, m in enumerate(order):
        lm, g, v = modes[m]
        if not np.array_equal(g, gids):
            raise InputError(src, f"{name} mode {m}", "the same grids in every mode")
        lam[j], phi[j] = lm, v[srt]
    gm = gk = None
    lama = c.lama[1::2]
    if lama:
        if len(lama) > 1:
            raise InputError(src, "LAMA", "the eigenvalues of one subcase", got=f"{len(lama)} tables")
        if len(lama[0]) % (7 * nb):
            raise InputError(src, "LAMA", "7 words per mode", got=f"{len(lama[0]) // nb} words")
        i, r = f"{e}i{nb}", f"{e}f{nb}"
        dt = np.dtype([("mode", i), ("order", i), ("eig", r), ("rad", r), ("cyc", r), ("gm", r), ("gk", r)])
        la = np.frombuffer(lama[0], dtype=dt)
        row = {int(m): k for k, m in enumerate(la["mode"])}
        missing = [m for m in order if m not in row]
        if missing:
            raise InputError(src, "LAMA", "every eigenvector's mode", got=f"mode {missing[0]} missing")
        k = [row[m] for m in order]
        eig = la["eig"][k].astype(float)
        with np.errstate(invalid="ignore"):
            same = np.allclose(eig, lam, rtol=1e-5, atol=1e-6 * max(1.0, float(np.nanmax(np.abs(lam), initial=0))))
        if not same:
            raise InputError(src, "LAMA", f"the eigenvalues of {name}", got="different eigenvalues")
        gm, gk = la["gm"][k].astype(float), la["gk"][k].astype(float)
    return Op2Modes(np.array(order), lam, gm, gk, gids[srt], phi, name, e, nb)
