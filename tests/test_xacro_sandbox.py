"""A robot description runs no code: xacro's `${...}` and `$(eval ...)` go through our interpreter
(runner/compile/xacro_sandbox.py), never Python's `eval`.

The hostile corpus is drawn from known escapes of Python sandboxes (nested code objects, comprehensions,
attribute chains to `__globals__`/`__subclasses__`, format strings, builtins, NFKC-folded names, memory
and CPU bombs). Each one sits in a property used in an `<origin>`, tries to create a canary file, and must
be refused with the file and line of the expression; all go through the compile path in-process, a
handful through the real `scenario validate` and `scenario run`.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path
from xml.sax.saxutils import escape

import pytest

from runner.compile import xacro_sandbox
from runner.compile.packages import PackageMap
from runner.compile.xacro_expand import XacroError, expand
from tests.conftest import run_cli

EXPR_LINE = 4  # the line of the `evil` property below
ROBOT = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="rp" value=")"/>
  <xacro:property name="evil" value="{expr}"/>
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="${{evil}} 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></visual>
  </link>
</robot>
"""
REFUSED = "not allowed in a robot description"
TOUCH = "touch CANARY"

# (id, expression, what the error says). `${rp}` is ")": the text of `$(eval ...)` cannot hold one, and
# `${...}` cannot hold a "}" (xacro's lexer), so format-string escapes are written in `$(eval ...)`.
ESCAPES: list[tuple[str, str, str]] = [
    (
        "issue-lambda-globals",
        f"${{(lambda f: f.__globals__)(xacro.tokenize)['os'].system('{TOUCH}')}}",
        REFUSED,
    ),
    ("lambda-call", "${(lambda: open('CANARY', 'w'))()}", REFUSED),
    ("lambda-code-consts", "${(lambda: 0).__code__.co_consts}", REFUSED),
    ("listcomp-subclasses", "${[c for c in ().__class__.__base__.__subclasses__()]}", REFUSED),
    (
        "listcomp-popen",
        "${[x for x in ().__class__.__base__.__subclasses__() if x.__name__ == 'Popen'][0](['touch', 'CANARY'])}",
        REFUSED,
    ),
    ("genexp-frame", "${[g.gi_frame.f_back.f_globals for g in [(x for x in [1])]]}", REFUSED),
    ("tuple-class-bases", "${().__class__.__bases__[0].__subclasses__()}", REFUSED),
    ("list-class", "${[].__class__}", REFUSED),
    ("str-mro", "${'x'.__class__.__mro__[1].__subclasses__()}", REFUSED),
    ("getattr", "${getattr(xacro.tokenize, '__glo' + 'bals__')}", REFUSED),
    ("format-attribute", "$(eval '{0._' + '_class_' + '_}'.format(1${rp})", REFUSED),
    ("format-in-property", "$(eval str.format('{0.__class__}', 1${rp})", REFUSED),
    ("fstring-attribute", "$(eval f'{xacro}'.__class__)", REFUSED),
    ("fstring-nested-spec", "$(eval f'{1:{10**9}}')", REFUSED),
    ("vars", "${vars()}", REFUSED),
    ("python-vars", "${python.vars(xacro)}", REFUSED),
    ("python-type", "${python.type('X', (), dict(f=1))}", REFUSED),
    ("globals", "${globals()}", REFUSED),
    ("builtins", "${__builtins__}", REFUSED),
    ("import", f"${{__import__('os').system('{TOUCH}')}}", REFUSED),
    ("eval-import", "$(eval __import__('os'${rp}.system('touch CANARY'${rp})", REFUSED),
    ("xacro-os", f"${{xacro.os.system('{TOUCH}')}}", "'os' is not defined"),
    ("tokenize-globals", f"${{xacro.tokenize.__globals__['os'].system('{TOUCH}')}}", REFUSED),
    ("load-yaml-globals", "${load_yaml.__globals__['os']}", REFUSED),
    ("xacro-load-yaml-globals", "${xacro.load_yaml.__globals__['__builtins__']}", REFUSED),
    ("message-closure", "${xacro.message.__closure__[0].cell_contents}", REFUSED),
    ("fatal-code", "${xacro.fatal.__code__}", REFUSED),
    ("math-loader", "${math.__loader__}", REFUSED),
    ("math-self", "${math.sin.__self__}", REFUSED),
    ("walrus", "${(f := open)('CANARY', 'w')}", REFUSED),
    ("eval", f"${{eval(\"__import__('os').system('{TOUCH}')\")}}", REFUSED),
    ("exec", "${exec('open(1)')}", REFUSED),
    ("compile", "${compile('1', 'a', 'eval')}", REFUSED),
    ("open", "${open('CANARY', 'w')}", REFUSED),
    ("eval-open", "$(eval open('CANARY', 'w'${rp}.close(${rp})", REFUSED),
    ("breakpoint", "${breakpoint()}", REFUSED),
    ("help", "${help()}", REFUSED),
    ("exit", "${exit(3)}", REFUSED),
    ("nfkc-dunder-attribute", "${().__ｃｌａｓｓ__.__ｂａｓｅ__}", REFUSED),
    ("nfkc-name", "${𝓮𝓿𝓪𝓵('1')}", REFUSED),
    ("nfkc-globals", f"${{xacro.tokenize.__ｇｌｏｂａｌｓ__['os'].system('{TOUCH}')}}", REFUSED),
    ("string-built-key", "${xacro['_' + '_class__']}", REFUSED),
    ("string-built-attribute", "${python.sorted([3, 1], key=python.getattr)}", REFUSED),
    ("map-type", "${python.map(python.type, [1])}", REFUSED),
    ("element-attribute", "${xacro.dotify(dict(a=1)).__class__.__init__.__globals__}", REFUSED),
    ("power-bomb", "${10**10**10}", REFUSED),
    ("string-bomb", "${'a'*10**10}", REFUSED),
    ("list-bomb", "${[0]*10**10}", REFUSED),
    ("nested-list-bomb", "${[[0]*10**5]*10**5}", REFUSED),
    ("range-bomb", "${list(python.range(10**12))}", REFUSED),
    ("shift-bomb", "${1 << 10**9}", REFUSED),
    ("factorial-bomb", "${math.factorial(10**6)}", REFUSED),
    ("prod-bomb", "${math.prod(python.range(1, 10**5))}", REFUSED),
    ("round-bomb", "${round(5, -10**9)}", REFUSED),
    ("percent-width-bomb", "${'%*d' % (10**9, 1)}", REFUSED),
    ("replace-bomb", "${('-'*10**5).replace('-', '-'*10**5)}", REFUSED),
    ("comprehension-bomb", "${[[0]*999999 for i in python.range(100)]}", REFUSED),
    ("deep-expression", "${" + "-" * 5000 + "1}", REFUSED),
    ("sort-key-bomb", "${python.sorted([python.range(10**6)]*300000, key=list)}", REFUSED),
    ("scan-bomb", "${len([1 for i in python.range(30000) if [0]*300000 == [0]*300000])}", REFUSED),
    ("method-scan-bomb", "${python.sum([('a'*400000).count('a') for i in python.range(3000)])}", REFUSED),
]


def _describe(tmp_path: Path, expr: str) -> Path:
    canary = tmp_path / "CANARY"
    desc = tmp_path / "desc" / "robot.xacro"
    desc.parent.mkdir(exist_ok=True)
    desc.write_text(ROBOT.format(expr=escape(expr.replace("CANARY", str(canary)), {'"': "&quot;"})))
    return desc


def _expression_shown(expr: str) -> str:
    """The start of the expression as the error shows it (`${rp}` expanded inside `$(eval ...)`)."""
    return expr.replace("${rp}", ")").split("CANARY")[0][:14]


@pytest.mark.parametrize(("expr", "says"), [pytest.param(e, s, id=i) for i, e, s in ESCAPES])
def test_each_escape_is_refused_at_its_line_and_runs_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, expr: str, says: str
) -> None:
    monkeypatch.chdir(tmp_path)  # a relative canary would land here
    desc = _describe(tmp_path, expr)
    with pytest.raises(XacroError) as err:
        expand(desc, {}, PackageMap.for_scenario(tmp_path))
    e = err.value
    assert not (tmp_path / "CANARY").exists()
    assert (e.file, e.line) == (desc, EXPR_LINE), str(e)
    assert says in str(e)
    if says == REFUSED:
        assert _expression_shown(expr) in str(e)
        assert "arithmetic" in (e.hint or "") and "xacro.load_yaml" in (e.hint or "")


def test_the_corpus_is_large_and_every_entry_would_touch_or_reach_python() -> None:
    assert len(ESCAPES) >= 30
    assert len({i for i, _, _ in ESCAPES}) == len(ESCAPES)


# The escapes that ran code or exhausted memory before the sandbox, through the real CLI.
CLI_ESCAPES = [
    "issue-lambda-globals",
    "eval-open",
    "listcomp-popen",
    "python-type",
    "nfkc-globals",
    "string-bomb",
]


@pytest.mark.parametrize("name", CLI_ESCAPES)
def test_validate_and_run_refuse_an_escape_before_anything_runs(tmp_path: Path, name: str) -> None:
    expr = next(e for i, e, _ in ESCAPES if i == name)
    _describe(tmp_path, expr)
    scenario = tmp_path / "s.yaml"
    scenario.write_text("name: s\nduration: 2\nrobots:\n  - {name: r1, description: desc/robot.xacro}\n")
    for command in (["validate", str(scenario)], ["run", str(scenario), "--no-record", "-q"]):
        proc = run_cli(*command, timeout=120, cwd=tmp_path)
        out = " ".join((proc.stdout + proc.stderr).split())
        assert proc.returncode == 1, out
        assert "Traceback" not in out
        assert f"robot.xacro:{EXPR_LINE}:" in out and REFUSED in out and "robots[0].description" in out, out
        assert "hint:" in out and "arithmetic" in out, out
        assert not (tmp_path / "CANARY").exists()


def test_files_outside_the_trusted_folders_are_refused_before_they_are_opened(tmp_path: Path) -> None:
    """A named pipe outside the scenario's folder: opening it to read would block for ever (xacro read
    it, and the check came after the expansion)."""
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    os.mkfifo(outside / "params.yaml")
    os.mkfifo(outside / "parts.xacro")
    scenario_dir = tmp_path / "scenario"
    scenario_dir.mkdir()
    scenario = scenario_dir / "s.yaml"
    scenario.write_text("name: s\nduration: 1\nrobots:\n  - {name: r1, description: desc/robot.xacro}\n")
    for expr, read in [
        (f"${{xacro.load_yaml('{outside / 'params.yaml'}')['w']}}", "params.yaml"),
        ("${load_yaml('../../elsewhere/params.yaml')['w']}", "params.yaml"),
    ]:
        _describe(scenario_dir, expr)
        proc = run_cli("validate", str(scenario), timeout=60)
        out = " ".join((proc.stdout + proc.stderr).split())
        assert proc.returncode == 1 and f"{read} is outside the scenario's folder and packages" in out, out
        assert f"robot.xacro:{EXPR_LINE}:" in out
    desc = scenario_dir / "desc" / "robot.xacro"
    desc.write_text(
        ROBOT.format(expr="1").replace("<link", f'<xacro:include filename="{outside}/parts.xacro"/><link', 1)
    )
    proc = run_cli("validate", str(scenario), timeout=60)
    out = " ".join((proc.stdout + proc.stderr).split())
    assert proc.returncode == 1 and "parts.xacro is outside the scenario's folder and packages" in out, out


def test_tokenize_takes_its_separators_as_characters(tmp_path: Path) -> None:
    """xacro.tokenize built a regular expression from `sep`: this one backtracks for hours."""
    desc = _describe(
        tmp_path, "${len(xacro.tokenize('a'*40 + 'b', 'a](a|a)*c|[b') + xacro.tokenize('x,y z'))}"
    )
    scenario = tmp_path / "s.yaml"
    scenario.write_text("name: s\nduration: 1\nrobots:\n  - {name: r1, description: desc/robot.xacro}\n")
    start = time.monotonic()
    proc = run_cli("validate", str(scenario), timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert time.monotonic() - start < 60
    assert '<origin xyz="3 0 0"/>' in expand(desc, {}, PackageMap.for_scenario(tmp_path)).urdf


def test_expressions_that_work_too_long_are_stopped(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(xacro_sandbox, "MAX_WORK", 100_000)
    desc = _describe(tmp_path, "${len([1 for c in python.range(999999) for d in python.range(999999) if 0])}")
    with pytest.raises(XacroError) as err:
        expand(desc, {}, PackageMap.for_scenario(tmp_path))
    assert err.value.line == EXPR_LINE and "more than 100000 steps" in str(err.value)


# What real descriptions write, with the value xacro gives (xacro's own test suite passes with the sandbox,
# and the shipped and public descriptions we tried expand to the same URDF, byte for byte).
LEGIT: list[tuple[str, str]] = [
    ("${1+2*3}", "7"),
    ("${radians(90)}", str(math.pi / 2)),
    ("${pi/2}", str(math.pi / 2)),
    ("${-pi/2.0}", str(-math.pi / 2)),
    ("${sqrt(2)}", str(math.sqrt(2))),
    ("${math.sin(0.5)}", str(math.sin(0.5))),
    ("${cos(0)}", "1.0"),
    ("${0.0833333 * 2 * (3 * 0.1 * 0.1 + 0.2 * 0.2)}", str(0.0833333 * 2 * (3 * 0.1 * 0.1 + 0.2 * 0.2))),
    ("${load_yaml('cfg.yaml')['a']['b']}", "3"),
    ("${xacro.load_yaml('$(find desc)/cfg.yaml')['a']['c'][1]}", "2"),
    ("${xacro.load_yaml('cfg.yaml').a.b}", "3"),
    ("${xacro.load_yaml('cfg.yaml')['ang']}", str(math.pi / 2)),
    ("${[2*item for item in xacro.load_yaml('cfg.yaml').a.c][1]}", "4"),
    ("${len([1,2,3])}", "3"),
    ("${'a' + 'b'}", "ab"),
    ("${'a' in 'abc'}", "True"),
    ("${str(1.5) + 'm'}", "1.5m"),
    ("${int('3') + float('2.5')}", "5.5"),
    ("${1 if 2 &gt; 1 else 0}", "1"),
    ("${not False and (True or 0)}", "True"),
    ("${'continuous' != 'fixed'}", "True"),
    ("${max(1,2) + min(3, 4)}", "5"),
    ("${python.sorted([3,1])[0]}", "1"),
    ("${xacro.arg('w')}", "2"),
    ("$(arg w)", "2"),
    ("$(eval 1 + 2)", "3"),
    ("$(eval w * 3)", "6"),
    ("$(eval arg('w'${rp} * 2)", "4"),
    ("$(eval radians(180${rp})", str(math.pi)),
    ("${xacro.tokenize('a,b;c')[2]}", "c"),
    ("${'%.2f' % 1.2345}", "1.23"),
    ("${'a b'.split()[1].upper()}", "B"),
    ("${' '.join(['x','y'])}", "x y"),
    ("${round(1.2345, 2)}", "1.23"),
    ("${python.abs(-2) + python.sum([1,2])}", "5"),
    ("${list(map(float, '1 2 3'.split()))[2]}", "3.0"),
    ("${2**10 + 10 // 3}", "1027"),
    ("${python.range(3)[2]}", "2"),
    ("${dict(shoulder=0.0, elbow=-1.57)['elbow']}", "-1.57"),
    ("${[1,2,3][-1] + [1,2,3][1:][0] + (1,2)[0]}", "6"),
    ("${dict(k=2).get('k')}", "2"),
    ("${[a*b for a, b in python.zip([1,2], [3,4])][1]}", "8"),
    ("${python.isinstance(1, int)}", "True"),
]


@pytest.mark.parametrize(("expr", "value"), LEGIT)
def test_what_descriptions_write_still_works(tmp_path: Path, expr: str, value: str) -> None:
    (tmp_path / "desc").mkdir()
    (tmp_path / "desc" / "package.xml").write_text("<package format='3'><name>desc</name></package>")
    (tmp_path / "desc" / "cfg.yaml").write_text("a: {b: 3, c: [1, 2]}\nang: !degrees 90\n")
    desc = tmp_path / "desc" / "robot.xacro"
    desc.write_text(ROBOT.format(expr=expr))
    urdf = expand(desc, {"w": "2"}, PackageMap.for_scenario(tmp_path)).urdf
    assert f'<origin xyz="{value} 0 0"/>' in urdf
