"""One module per area of the report; each has ``build(ctx) -> Section``."""
