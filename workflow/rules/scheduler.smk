# Snakemake's scheduler, made to scale to the default report's ~1,100 jobs (issue 13).
#
# Before every scheduling round (one per finished job), Snakemake 9's JobScheduler asks
# the size of every input file of every ready job -- one asyncio task per file, ~1,000 per
# round once a study's per-trial jobs are ready -- only to prefer jobs with large inputs
# when it picks among them.  Measured on the default report (benchmarks/
# report_end_to_end.py): Snakemake's own process used 574 CPU-s of the run's 1,597, most of
# it there (py-spy: 16.5 % of all samples in update_input_sizes' event loop).  Here a file
# whose size is known is not asked again: the workflow never rewrites an input while the
# run goes on, so the sizes, and the job order they give, are the same.  Files not there yet
# (None) are asked again each round, as before.  If a Snakemake release renames the method,
# nothing is patched (the run is slower, not different).
try:
    from snakemake.scheduling.job_scheduler import JobScheduler as _JobScheduler
except ImportError:                      # another Snakemake layout: leave it alone
    _JobScheduler = None

if _JobScheduler is not None and hasattr(_JobScheduler, "update_input_sizes") and not getattr(
    _JobScheduler.update_input_sizes, "_gaitval_known_sizes", False
):
    _ask_input_sizes = _JobScheduler.update_input_sizes

    async def _update_unknown_input_sizes(self, jobs):
        jobs, known = list(jobs), self._input_sizes
        if len(known) > 9000:            # Snakemake trims its table past 10,000 files: as is
            return await _ask_input_sizes(self, jobs)
        unknown = [j for j in jobs if any(known.get(f) is None for f in j.input)]
        if unknown:
            await _ask_input_sizes(self, unknown)

    _update_unknown_input_sizes._gaitval_known_sizes = True
    _JobScheduler.update_input_sizes = _update_unknown_input_sizes

# Second: with its default job rate limit (--max-jobs-per-timespan 100/1s), every
# scheduling round ends by starting a timer thread that starts another round a second later
# -- and that round starts another timer.  Each finished job thus adds one more perpetual
# chain of rounds: after k jobs, about k rounds a second, each going over the ready and
# remaining jobs (py-spy of Snakemake during the default study's ingest + register:
# 44.7 % of its busy samples in these timers, after the first fix).  Here a round starts a
# timer only when none is pending: still a round within the timespan whenever one is asked
# for (what the rate limit and the queue-input wait need), never a pile of them.
if _JobScheduler is not None and hasattr(_JobScheduler, "_schedule_reevalutation") and not getattr(
    _JobScheduler._schedule_reevalutation, "_gaitval_one_timer", False
):
    import threading as _threading

    def _schedule_one_reevaluation(self, delay):
        with _GV_TIMER_LOCK:
            pending = getattr(self, "_gaitval_timer", None)
            if pending is not None and pending.is_alive():
                return

            def fire():
                with _GV_TIMER_LOCK:
                    self._gaitval_timer = None
                self._open_jobs.release()

            self._gaitval_timer = _threading.Timer(delay, fire)
            self._gaitval_timer.daemon = True
            self._gaitval_timer.start()

    _schedule_one_reevaluation._gaitval_one_timer = True
    _GV_TIMER_LOCK = _threading.Lock()
    _JobScheduler._schedule_reevalutation = _schedule_one_reevaluation
