"""What help() shows a notebook user: every public function, class, method and property
has its own text, and the signatures help() prints match docs/python.md."""
import inspect
import re

import pytest

import sahara


def own_text(obj):
    """The docstring without pybind11's signature line(s)."""
    doc = inspect.getdoc(obj) or ""
    lines = [line for line in doc.splitlines() if not re.match(r"^\w*\(.*\)( -> .*)?$", line)]
    return "\n".join(lines).strip()


def public_members():
    for name in sahara.__all__:
        obj = getattr(sahara, name)
        if name.startswith("__"):
            continue
        yield name, obj
        if inspect.isclass(obj) and name != "Image":  # Image's members are numpy's
            for member, value in vars(obj).items():
                if not member.startswith("_") or member == "__init__":
                    yield f"{name}.{member}", value


@pytest.mark.parametrize("name, obj", list(public_members()), ids=lambda v: v if isinstance(v, str) else "")
def test_every_public_name_has_a_docstring(name, obj):
    assert len(own_text(obj)) > 20, f"help(sahara.{name}) shows no description"


def documented_calls(repo):
    """`sahara.NAME(args)` and `Class.NAME(args)` as docs/python.md writes them."""
    text = (repo / "docs" / "python.md").read_text()
    return set(re.findall(r"`(?:sahara\.)?(\w+(?:\.\w+)?)\(([^`]*?)\)", text))


def argument_names(text):
    return [a.split("=")[0].strip() for a in text.split(",") if a.strip() and a.strip() != "*"]


def test_keyword_only_arguments_are_documented_as_such(repo):
    """RayCaster's threads is keyword-only: the docs must not show it as a third positional."""
    calls = documented_calls(repo)
    for name, args in calls:
        if name in ("RayCaster", "RayCaster.from_file", "sahara.RayCaster") and "threads" in args:
            assert "*," in args, f"{name}({args}) hides that threads is keyword-only"
    with pytest.raises(TypeError):
        sahara.RayCaster([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], 2)
    assert "threads" in sahara.RayCaster.from_file.__doc__.split("\n")[0]


def test_documented_python_functions_have_the_documented_arguments(repo):
    calls = dict(documented_calls(repo))
    for name in ("render", "write_image", "read_image"):
        assert name in calls, f"docs/python.md does not show sahara.{name}(...)"
        assert argument_names(calls[name]) == list(inspect.signature(getattr(sahara, name)).parameters)
