from granulargas.cli import main

raise SystemExit(main())
