from arena.match.child import main

raise SystemExit(main())
