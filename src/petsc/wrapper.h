#include <petscsnes.h>
#include <petscksp.h>
#include <petscmat.h>
#include <petscvec.h>
#include <petscis.h>
#include <petsclog.h>
