# The agreement_files entries and the options of `gaitval peer` for each (rules in
# workflow/rules/peer.smk).


# A study's own paired results (config agreement_files: name -> {path, system, reference,
# subject, units}, issue 37): per walk or stride, a system's value beside its reference's
# (a vendor's gait software against the mocap, say), analysed as the peer's worked example
# is -- pooled and repeated-measures agreement -- into tables/peer_<name>.  Each file is
# checked at start; the entry is a param, so an edited entry reruns its own table.
# The peer's worked example (config peer_results) belongs to the shipped studies' reports
# only: a run with a lab's own study (a trial sheet of its own, no `simulate:`) reports that
# study, and does not depend on the file (which lives in ../shared/ beside the checkout).
PEER_EXAMPLE = (
    str(config["peer_results"])
    if config.get("peer_results")
    and Path(config["peer_results"]).is_file()
    and all(is_simulated(s) for s in config["run"])
    else ""
)


AGREEMENT_FILES = dict(config.get("agreement_files") or {})
for _name, _entry in AGREEMENT_FILES.items():
    if not Path(_entry["path"]).is_file():
        sys.exit(f"ConfigError: agreement_files.{_name}.path: {_entry['path']!r} is not a "
                 "file (paths are relative to the working directory)")


def agreement_options(name):
    """`gaitval peer`'s options for agreement_files.<name>."""
    e = AGREEMENT_FILES[name]
    units = sorted((e.get("units") or {}).items())
    return (["--name", name, "--system-prefix", e.get("system", "us_"),
             "--reference-prefix", e.get("reference", "gt_")]
            + (["--subject", e["subject"]] if e.get("subject") else [])
            + (["--units", *(f"{k}={v}" for k, v in units)] if units else []))
