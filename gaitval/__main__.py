import sys

from gaitval.cli import main
from gaitval.jobs.lifeline import verb_process

verb_process()          # started by a workflow's job: end with its Snakemake (jobs/lifeline.py)
sys.exit(main())
