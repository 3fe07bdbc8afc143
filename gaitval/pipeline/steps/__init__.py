"""Pipeline steps at file level: read the files of one rule, call the library, write files.

One function per rule family; :mod:`gaitval.cli` exposes each as a verb and the Snakemake
rules call those verbs.  The library functions they call take objects and return objects;
only these modules and :mod:`gaitval.io` know where files live.  By concern:

- :mod:`~gaitval.pipeline.steps.config`: the study's analysis config, the per-job views of
  it, the method definitions they resolve;
- :mod:`~gaitval.pipeline.steps.trials`: one trial's sheet row, subject and ingested data;
- :mod:`~gaitval.pipeline.steps.register`: registration and ground truth, the
  registration table;
- :mod:`~gaitval.pipeline.steps.tracking`: one tracker or detector on one LRS trial;
- :mod:`~gaitval.pipeline.steps.tug`: TUG evaluation and tables;
- :mod:`~gaitval.pipeline.steps.ultrasonic`: seed 003's noise, tracks, gait parameters,
  tables and the agreement of several systems;
- :mod:`~gaitval.pipeline.steps.declarations`: external trackers and detectors a study
  declares, and the start-up checks of their files;
- :mod:`~gaitval.pipeline.steps.external`: export and import of tracks and detections in
  the exchange formats;
- :mod:`~gaitval.pipeline.steps.checks`: what ``gaitval validate`` reports of a study's
  own files.
"""
