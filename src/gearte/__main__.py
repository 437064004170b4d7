from gearte.cli import main

main()
