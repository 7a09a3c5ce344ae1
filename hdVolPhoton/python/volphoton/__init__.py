"""hdVolPhoton Python tools: USD schema reader/validator (volphoton.schema) and helpers."""
