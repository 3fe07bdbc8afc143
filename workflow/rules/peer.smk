# Worked example: gaitval's agreement statistics on a peer's published paired results
# (config key peer_results; skipped when the file is absent, e.g. without ../shared).


rule peer_agreement:
    input:
        config.get("peer_results", ""),
    output:
        csv=report(
            f"{REPORTS}/tables/peer_agreement.csv",
            caption="../report/peer.rst",
            category="Peer data",
        ),
        md=f"{REPORTS}/tables/peer_agreement.md",
        tex=f"{REPORTS}/tables/peer_agreement.tex",
    params:
        stem=lambda w, output: output.csv[: -len(".csv")],
        reports=parent_of("csv", up=1),
        chash=config_hash_when_run,
    log:
        "logs/peer_agreement.log",
    run:
        run_verb_job(
            verb("peer", input[0], "--out-stem", params.stem, "--reports-dir", params.reports,
                 "--config-hash", params.chash),
            log[0],
        )


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/peer_agreement.csv"]
        if config.get("peer_results") and Path(config["peer_results"]).is_file()
        else []
    )
)


# A study's own paired results (config agreement_files: name -> {path, system, reference,
# subject, units}, issue 37): per walk or stride, a system's value beside its reference's
# (a vendor's gait software against the mocap, say), analysed as the peer's worked example
# is -- pooled and repeated-measures agreement -- into tables/peer_<name>.  Each file is
# checked at start; the entry is a param, so an edited entry reruns its own table.
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


rule agreement_file:
    input:
        lambda w: AGREEMENT_FILES[w.name]["path"],
    output:
        csv=report(f"{REPORTS}/tables/peer_{{name}}.csv", category="Agreement"),
        md=f"{REPORTS}/tables/peer_{{name}}.md",
        tex=f"{REPORTS}/tables/peer_{{name}}.tex",
    wildcard_constraints:
        name="|".join(re.escape(n) for n in AGREEMENT_FILES) or "(?!x)x",
    params:
        entry=lambda w: json.dumps(AGREEMENT_FILES[w.name], sort_keys=True),
        opts=lambda w: agreement_options(w.name),
        stem=lambda w, output: output.csv[: -len(".csv")],
        reports=parent_of("csv", up=1),
        chash=config_hash_when_run,
    log:
        "logs/agreement_file/{name}.log",
    run:
        run_verb_job(
            verb("peer", input[0], params.opts, "--out-stem", params.stem,
                 "--reports-dir", params.reports, "--config-hash", params.chash),
            log[0],
        )


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/tables/peer_{n}.csv" for n in AGREEMENT_FILES]
)
