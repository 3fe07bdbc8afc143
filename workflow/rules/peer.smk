# Worked example: gaitval's agreement statistics on a peer's published paired results
# (config key peer_results; skipped when the file is absent, e.g. without ../shared, and
# in a run with a lab's own study: PEER_EXAMPLE in peer_common.smk).
include: "peer_common.smk"


rule peer_agreement:
    input:
        [PEER_EXAMPLE] if PEER_EXAMPLE else [],
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
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval peer {input:q} --out-stem {params.stem:q} --reports-dir {params.reports:q}"
        " --config-hash {params.chash:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: (
        [f"{REPORTS}/tables/peer_agreement.csv"] if PEER_EXAMPLE else []
    )
)


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
    conda:
        CONDA_ENV
    shell:
        "python -m gaitval peer {input:q} {params.opts:q} --out-stem {params.stem:q}"
        " --reports-dir {params.reports:q} --config-hash {params.chash:q} > {log:q} 2>&1"


REPORT_ITEM_FUNCS.append(
    lambda study: [f"{REPORTS}/tables/peer_{n}.csv" for n in AGREEMENT_FILES]
)
