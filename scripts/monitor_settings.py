"""A monitor settings file (config/monitor*.yaml: sections of `key: value` lines, comments) with settings changed, for
the evaluation scripts (scripts/campaign, scripts/evaluate_vehicle): one parser of `--set SECTION.KEY=VALUE`, one
check of its keys against config/monitor.yaml (which lists every setting with its default and unit), one editor. The
monitor itself validates the values when it reads the file (config.c)."""
import hashlib
import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REFERENCE = os.path.join(ROOT, "config", "monitor.yaml")


def _header(ln):
    """The section a line opens, or None."""
    return ln.split(":")[0].strip() if ln and not ln.startswith((" ", "\t", "#")) else None


def _key(ln):
    """The key an indented `key: value` line sets, or None (a comment, a blank or a header)."""
    return ln.strip().split(":")[0] if ln.startswith((" ", "\t")) and ":" in ln and not ln.strip().startswith("#") \
        else None


def sections(text):
    """{(section, key)} of a settings file's text."""
    found, section = set(), None
    for ln in text.splitlines():
        section = _header(ln) or section
        if _key(ln) is not None:
            found.add((section, _key(ln)))
    return found


def parse_sets(items, reserved=()):
    """`--set` items (SECTION.KEY=VALUE) as {(section, key): value}; ValueError naming the first item that is not of
    that form, sets a reserved key (the caller's own) or names no setting of config/monitor.yaml."""
    known = sections(open(REFERENCE).read())
    out = {}
    for item in items:
        if not re.fullmatch(r"[a-z_]+\.[a-z_0-9]+=\S+", item):
            raise ValueError(f"'{item}' is not section.key=value")
        name, value = item.split("=", 1)
        key = tuple(name.split("."))
        if name in reserved:
            raise ValueError(f"{name} is the script's own")
        if key not in known:
            raise ValueError(f"{name}: not a setting of config/monitor.yaml")
        out[key] = value
    return out


def tag(settings):
    """A short name for a set of settings (the cache file's suffix; '' for none)."""
    return hashlib.sha1(repr(sorted(settings.items())).encode()).hexdigest()[:8] if settings else ""


def edited(text, settings, drop=()):
    """text with each (section, key) of settings given its value (the key's line replaced where its section has it,
    else added under the section, the section added at the end where absent), the keys of drop left out (unless
    set), and a section left without keys removed (an empty section is no mapping: the monitor refuses it)."""
    lines, section, done = [], None, set()
    for ln in text.splitlines():
        section, key = _header(ln) or section, _key(ln)
        if key is not None and (section, key) in settings:
            ln = f"{ln[:len(ln) - len(ln.lstrip())]}{key}: {settings[(section, key)]}"
            done.add((section, key))
        elif key is not None and (section, key) in drop:
            continue
        lines.append(ln)
    for (section, key), value in settings.items():
        if (section, key) in done:
            continue
        if f"{section}:" not in lines:
            lines.append(f"{section}:")
        lines.insert(lines.index(f"{section}:") + 1, f"  {key}: {value}")

    def has_keys(k):  # a section header keeps a key below it
        for ln in lines[k + 1:]:
            if ln.strip() and not ln.lstrip().startswith("#"):
                return ln.startswith((" ", "\t"))
        return False
    kept = [ln for k, ln in enumerate(lines) if not (_header(ln) and ln.rstrip().endswith(":") and not has_keys(k))]
    return "\n".join(kept) + "\n"
