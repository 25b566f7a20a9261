from housingfe.cli import main

raise SystemExit(main())
