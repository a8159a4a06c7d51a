"""SPC at the machine and the Q-DAS AQDEF (DFQ) export of a part series (design.md §10.3,
docs/results.md). Reads the characteristics that ``ResultsService`` wrote; statistics from
``engine.verdict.series_statistics``."""

from __future__ import annotations

from datetime import datetime

from app.errors import InvalidInput, NotFoundError
from app.services.results import ResultsService
from db import Database
from engine.verdict import series_statistics

DFQ_ENCODING = "cp1252"          # AQDEF transfer files: Windows-1252 text, CR LF line ends
DFQ_DECIMALS = 4


def _part_number(value: str | None) -> str:
    if not value or len(value) > 64:
        raise InvalidInput("part_number: the part number of the series (1..64 characters)", field="part_number")
    return value


def _dfq_text(value) -> str:
    """A K-field value on one line: no line breaks, no control characters."""
    return "".join(ch if ch.isprintable() else " " for ch in str(value)).strip()


def _dfq_number(value: float) -> str:
    return f"{value:.{DFQ_DECIMALS + 2}f}".rstrip("0").rstrip(".") if value == value else ""


def _dfq_time(iso: str) -> str:
    """AQDEF date/time ``dd.mm.yyyy/hh:mm:ss`` in the machine's local time."""
    return datetime.fromisoformat(iso).astimezone().strftime("%d.%m.%Y/%H:%M:%S")


class QualityService:
    def __init__(self, db: Database, results: ResultsService):
        self._db = db
        self._results = results

    def spc(self, part_number: str | None, characteristic: str | None) -> dict:
        """The run chart data and statistics of one characteristic over the parts of ``part_number``."""
        part_number = _part_number(part_number)
        if not characteristic or len(characteristic) > 80:
            raise InvalidInput("characteristic: the name of a characteristic", field="characteristic")
        rows = self._results.series(part_number, characteristic)
        if not rows:
            raise NotFoundError(f"no values of {characteristic!r} for part number {part_number!r}",
                                field="characteristic")
        values = [r["actual"] for r in rows if r["actual"] is not None]
        last = rows[-1]
        stats = series_statistics(values, last["lower"], last["upper"])
        return {"part_number": part_number, "characteristic": characteristic, "unit": last["unit"],
                "nominal": last["nominal"], "lower": last["lower"], "upper": last["upper"],
                "n": stats.n, "values": values, "mean": stats.mean, "sigma": stats.sigma,
                "sigma_within": stats.sigma_within, "ucl": stats.ucl, "lcl": stats.lcl,
                "cp": stats.cp, "cpk": stats.cpk, "pp": stats.pp, "ppk": stats.ppk,
                "points": [{"part_id": r["part"]["id"], "serial": r["part"]["serial"], "value": r["actual"],
                            "time": r["time"], "verdict": r["verdict"], "compensation": r["compensation"],
                            "log_id": r["log_id"]} for r in rows]}

    def characteristic_names(self, part_number: str) -> list[str]:
        return list(dict.fromkeys(r["name"] for r in self._results.series(part_number)))

    def dfq(self, part_number: str | None) -> str:
        """AQDEF (DFQ) text of every part of ``part_number`` (K-field format, one line per field)."""
        part_number = _part_number(part_number)
        rows = self._results.series(part_number)
        if not rows:
            raise NotFoundError(f"no measured parts of part number {part_number!r}", field="part_number")
        names = list(dict.fromkeys(r["name"] for r in rows))
        index = {name: k for k, name in enumerate(names, start=1)}
        last = {r["name"]: r for r in rows}
        gauges = self._gauges({r["log_id"] for r in rows if r["log_id"] is not None})
        lines = [f"K0100 {len(names)}", f"K1001 {_dfq_text(part_number)}", f"K1002 {_dfq_text(part_number)}"]
        order = rows[-1]["part"].get("order")
        if order:
            lines.append(f"K1053 {_dfq_text(order)}")
        for name in names:
            k, c = index[name], last[name]
            lines += [f"K2001/{k} {k}", f"K2002/{k} {_dfq_text(name)}"]
            for field, value in (("K2101", c["nominal"]), ("K2110", c["lower"]), ("K2111", c["upper"])):
                if value is not None:
                    lines.append(f"{field}/{k} {_dfq_number(value)}")
            lines += [f"K2142/{k} {c['unit']}", f"K2022/{k} {DFQ_DECIMALS}"]
        for r in rows:                         # measuring order: part by part, its values
            if r["actual"] is None:
                continue
            k, part = index[r["name"]], r["part"]
            lines += [f"K0001/{k} {_dfq_number(r['actual'])}", f"K0004/{k} {_dfq_time(r['time'])}"]
            if part.get("serial"):
                lines.append(f"K0006/{k} {_dfq_text(part['serial'])}")
            if part.get("operator"):
                lines.append(f"K0008/{k} {_dfq_text(part['operator'])}")
            lines.append(f"K0012/{k} {gauges.get(r['log_id'], 'probe')}")
        return "\r\n".join(lines) + "\r\n"

    def _gauges(self, log_ids: set[int]) -> dict[int, str]:
        """The gauge of each value: the workpiece probe record it was measured with."""
        out = {}
        with self._db.unit(readonly=True) as unit:
            for log_id in log_ids:
                entry = unit.get_log(log_id) or {}
                probe: dict = entry["probe"] if isinstance(entry.get("probe"), dict) else {}
                out[log_id] = f"probe {probe['number']}" if probe.get("number") else "probe"
        return out
