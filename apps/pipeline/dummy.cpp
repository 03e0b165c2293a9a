// Keeps dpc_pipeline non-empty before the pipeline sources exist.
