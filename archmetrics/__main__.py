from archmetrics.cli import main

raise SystemExit(main())
