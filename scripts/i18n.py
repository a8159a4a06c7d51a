"""The screens' message catalogues (app/i18n.py, design.md §9.9): extract, update, check, compile.

    python scripts/i18n.py extract   # app/locale/messages.pot from the code, templates and tables
    python scripts/i18n.py update    # merge the .pot into app/locale/{de,zh}/LC_MESSAGES/messages.po
    python scripts/i18n.py check     # untranslated / fuzzy counts per language (exit 1 on a broken .po)
    python scripts/i18n.py compile   # write the .mo files (optional: app/i18n.py compiles in memory)

Besides the ``_``/``N_``/``gettext``/``Text`` calls of app/ and templates/ (Babel's python and
jinja2 extractors, the same as ``pybabel extract -F babel.cfg``), the catalogue takes the texts of
tables that are data, not calls: the settings' labels (app/gud.py), the alarm texts and remedies
(engine/alarms.py) and the measuring fields' labels and choices (app/workflow/forms.py).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

from babel.messages.catalog import Catalog
from babel.messages.extract import extract_from_dir
from babel.messages.mofile import write_mo
from babel.messages.pofile import read_po, write_po

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

LOCALE = ROOT / "app" / "locale"
POT = LOCALE / "messages.pot"
LANGS = ("de", "zh")
KEYWORDS = {"_": None, "N_": None, "gettext": None, "ngettext": (1, 2), "Text": None}
METHODS = [("app/locale/**", "ignore"), ("app/**.py", "python"), ("templates/**.html", "jinja2")]
OPTIONS = {"templates/**.html": {"extensions": "jinja2.ext.i18n", "trimmed": "true"}}
DATA_FILES = ("app/workflow/forms.py",)        # string constants of FieldSpec(...) calls
FIELD_CALLS = ("FieldSpec", "_yes_no")         # (name, label, ...): the helpers that build a FieldSpec


def _field_texts(path: Path):
    """Label and choice texts of every ``FieldSpec(...)`` (or ``_yes_no(...)``) in ``path``: plain strings only (an
    f-string label is translated by its pattern, app/web/texts.py ``label_text``)."""
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Call) and getattr(node.func, "id", "") in FIELD_CALLS):
            continue
        labels = list(node.args[1:2]) + [k.value for k in node.keywords if k.arg == "label"]
        for choices in [k.value for k in node.keywords if k.arg == "choices"]:
            labels += [t.elts[1] for t in ast.walk(choices) if isinstance(t, ast.Tuple) and len(t.elts) == 2]
        for arg in labels:
            if isinstance(arg, ast.Constant) and isinstance(arg.value, str) and arg.value.strip():
                yield arg.lineno, arg.value


def collect() -> Catalog:
    """Every text the screens show, from the code, the templates and the data tables."""
    catalog = Catalog(project="Measure-in-JOG HMI", charset="utf-8")
    for filename, lineno, message, comments, _context in extract_from_dir(
            str(ROOT), METHODS, keywords=KEYWORDS, options_map=OPTIONS, strip_comment_tags=True):
        catalog.add(message, locations=[(filename, lineno)], auto_comments=comments)
    from app.gud import GudSettings, field_groups
    from engine import alarms

    for group, _fields in field_groups():
        catalog.add(group, locations=[("app/gud.py", 0)])
    for name, info in GudSettings.model_fields.items():
        if info.description:
            catalog.add(info.description, locations=[("app/gud.py", 0)], auto_comments=[name])
    for alarm in alarms.all_alarms():
        catalog.add(alarm.text, locations=[("engine/alarms.py", 0)], auto_comments=[f"alarm {alarm.number}"])
        if alarm.remedy:
            catalog.add(alarm.remedy, locations=[("engine/alarms.py", 0)],
                        auto_comments=[f"remedy of alarm {alarm.number}"])
    for rel in DATA_FILES:
        for lineno, text in _field_texts(ROOT / rel):
            if not text.isdigit() and text not in ("+", "-", "−"):
                catalog.add(text, locations=[(rel, lineno)])
    return catalog


def extract() -> Catalog:
    catalog = collect()
    LOCALE.mkdir(parents=True, exist_ok=True)
    with POT.open("wb") as fp:
        write_po(fp, catalog, width=100, sort_by_file=False)
    print(f"{POT.relative_to(ROOT)}: {len(catalog)} texts")
    return catalog


def po_path(lang: str) -> Path:
    return LOCALE / lang / "LC_MESSAGES" / "messages.po"


def read(path: Path, lang: str) -> Catalog:
    with path.open("rb") as fp:
        return read_po(fp, locale=lang)


def write(path: Path, catalog: Catalog) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as fp:
        write_po(fp, catalog, width=100, omit_header=False, ignore_obsolete=True)


def update() -> None:
    template = read(POT, "en")
    for lang in LANGS:
        path = po_path(lang)
        catalog = read(path, lang) if path.exists() else Catalog(locale=lang, charset="utf-8")
        catalog.update(template, no_fuzzy_matching=True)
        write(path, catalog)
        print(f"{path.relative_to(ROOT)}: {len(catalog)} texts")


def check() -> int:
    for lang in LANGS:
        catalog = read(po_path(lang), lang)
        missing = [m.id for m in catalog if m.id and not m.string]
        fuzzy = [m.id for m in catalog if m.id and m.fuzzy]
        print(f"{lang}: {len(catalog)} texts, {len(missing)} untranslated, {len(fuzzy)} fuzzy")
    return 0


def compile_mo() -> None:
    for lang in LANGS:
        path = po_path(lang)
        with path.with_suffix(".mo").open("wb") as fp:
            write_mo(fp, read(path, lang), use_fuzzy=False)
        print(f"{path.with_suffix('.mo').relative_to(ROOT)}")


if __name__ == "__main__":
    command = sys.argv[1] if len(sys.argv) > 1 else "check"
    actions = {"extract": extract, "update": update, "check": check, "compile": compile_mo}
    if command not in actions:
        sys.exit(__doc__)
    sys.exit(actions[command]() if command == "check" else actions[command]() and 0)
