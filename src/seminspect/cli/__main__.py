from seminspect.cli import main

main()
