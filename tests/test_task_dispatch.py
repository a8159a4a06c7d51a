"""No dispatch on task-name strings (issue 27 item 3): a task's behaviour comes from its entry in
the task registry (app/workflow/tasks.py, engine.turning_plan.LATHE_TASK_RULES), never from
``task == "lathe.point"`` or ``task.startswith("lathe.tool")`` somewhere else."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# a task compared with a lathe task's name, or a name tested for a task-family prefix
DISPATCH = re.compile(r"""(==|!=|\bin)\s*\(?\s*["']lathe\.[a-z_.]*["']"""
                      r"""|\.startswith\(\s*\(?\s*["'](lathe|tool|probe|spigot)\b""")


def _sources():
    for folder in ("app", "engine"):
        yield from sorted((ROOT / folder).rglob("*.py"))


def test_the_pattern_finds_what_it_forbids():
    for line in ('if task == "lathe.point":', 'if task in ("lathe.tool.measure", "lathe.tool.auto"):',
                 'if task.startswith("lathe.tool"):', 'spigot = task.startswith("spigot")'):
        assert DISPATCH.search(line), line
    for line in ('_lathe("lathe.point", Category.WORKPIECE)', '"lathe.point": LatheTaskRules(...)',
                 'if key.startswith("tolerance."):'):
        assert not DISPATCH.search(line), line


def test_no_module_dispatches_on_a_task_name():
    found = [f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
             for path in _sources() for n, line in enumerate(path.read_text().splitlines(), 1)
             if DISPATCH.search(line)]
    assert not found, "task-name dispatch (use the task's registry entry):\n" + "\n".join(found)
