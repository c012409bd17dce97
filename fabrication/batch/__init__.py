"""Batch: many drawings to files on every core, or on a Dask cluster.

`find_inputs` (files and folders -> `BatchItem`s with mirrored output paths), `process_file`
(the per-file function: one drawing to the bytes of each target, the same library calls as
the single commands), `run_batch` (skip what is current, run the rest on a process pool or
a Dask cluster, write outputs atomically, the manifest and the CSV/JSON report).
"""

from fabrication.batch.inputs import BatchItem, find_inputs
from fabrication.batch.report import BatchSummary, FileRecord, FileStats
from fabrication.batch.runner import run_batch
from fabrication.batch.work import (INPUT_EXTENSIONS, BatchJob, DrawingTarget, EmbroideryTarget, FileResult,
                                    LaserTarget, process_file)

__all__ = ["BatchItem", "BatchJob", "BatchSummary", "DrawingTarget", "EmbroideryTarget", "FileRecord",
           "FileResult", "FileStats", "INPUT_EXTENSIONS", "LaserTarget", "find_inputs", "process_file", "run_batch"]
