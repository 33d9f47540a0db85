(Scribbled version of /tmp/ink_ext_XXXXXX.svg40EVQY @ 3500.00)
( unicorn.py --tab="plotter_setup" --pen-up-angle=50 --pen-down-angle=30 --start-delay=150 --stop-delay=150 --xy-feedrate=3500 --z-feedrate=150 --z-height=0 --finished-height=0 --register-pen=true --x-home=0 --y-home=0 --num-copies=1 --continuous=false --pause-on-layer-change=false /tmp/ink_ext_XXXXXX.svg40EVQY )
G21 (metric ftw)
G90 (absolute mode)
G92 X0.00 Y0.00 Z0.00 (you are here)

M300 S30 (pen down)
G4 P150 (wait 150ms)
M300 S50 (pen up)
G4 P150 (wait 150ms)
M18 (disengage drives)
M01 (Was registration test successful?)
M17 (engage drives if YES, and continue)

(Polyline consisting of 3 segments.)
G1 X-35.73 Y19.68 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-35.73 Y13.76 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 3 segments.)
G1 X-31.78 Y19.68 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-31.78 Y13.76 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 3 segments.)
G1 X-35.73 Y16.86 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-31.78 Y16.86 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 4 segments.)
G1 X-29.52 Y19.68 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-29.52 Y13.76 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 4 segments.)
G1 X-29.52 Y19.68 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-25.85 Y19.68 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 4 segments.)
G1 X-29.52 Y16.86 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-27.26 Y16.86 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 4 segments.)
G1 X-29.52 Y13.76 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-25.85 Y13.76 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 2 segments.)
G1 X-24.16 Y19.68 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-24.16 Y13.76 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 2 segments.)
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-20.77 Y13.76 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 2 segments.)
G1 X-19.36 Y19.68 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-19.36 Y13.76 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 2 segments.)
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-15.97 Y13.76 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 1 segments.)
G1 X-13.15 Y19.68 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-13.72 Y19.40 F3500.00
G1 X-14.28 Y18.84 F3500.00
G1 X-14.56 Y18.27 F3500.00
G1 X-14.85 Y17.43 F3500.00
G1 X-14.85 Y16.02 F3500.00
G1 X-14.56 Y15.17 F3500.00
G1 X-14.28 Y14.60 F3500.00
G1 X-13.72 Y14.04 F3500.00
G1 X-13.15 Y13.76 F3500.00
G1 X-12.02 Y13.76 F3500.00
G1 X-11.46 Y14.04 F3500.00
G1 X-10.89 Y14.60 F3500.00
G1 X-10.61 Y15.17 F3500.00
G1 X-10.33 Y16.02 F3500.00
G1 X-10.33 Y17.43 F3500.00
G1 X-10.61 Y18.27 F3500.00
G1 X-10.89 Y18.84 F3500.00
G1 X-11.46 Y19.40 F3500.00
G1 X-12.02 Y19.68 F3500.00
G1 X-13.15 Y19.68 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 1 segments.)
G1 X-35.15 Y6.60 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X-34.66 Y8.39 F3500.00
G1 X-34.52 Y7.85 F3500.00
G1 X-33.37 Y9.78 F3500.00
G1 X-33.26 Y9.59 F3500.00
G1 X-34.41 Y7.66 F3500.00
G1 X-34.09 Y7.43 F3500.00
G1 X-35.15 Y6.60 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)

(Polyline consisting of 1 segments.)
G1 X24.24 Y6.60 F3500.00
M300 S30.00 (pen down)
G4 P150 (wait 150ms)
G1 X24.73 Y8.39 F3500.00
G1 X24.87 Y7.85 F3500.00
G1 X26.01 Y9.78 F3500.00
G1 X26.13 Y9.59 F3500.00
G1 X24.98 Y7.66 F3500.00
G1 X25.30 Y7.43 F3500.00
G1 X24.24 Y6.60 F3500.00
M300 S50.00 (pen up)
G4 P150 (wait 150ms)


(end of print job)
M300 S50.00 (pen up)
G4 P150 (wait 150ms)
M300 S255 (turn off servo)
G1 X0 Y0 F3500.00
G1 Z0.00 F150.00 (go up to finished level)
G1 X0.00 Y0.00 F3500.00 (go home)
M18 (drives off)
