"""Tools at the top of the suite (they may use every layer): process launching, ``att-demo``,
``att-review``, ``att-bench``, ``att-tune`` and the soak run."""
