/* A C program on MoorDyn's C API (the library the moordyn wheel ships), as a compiled mooring
 * FMU would call it: create from a file, initialise with one coupled body at rest, give the
 * water kinematics (still water here), step with a prescribed surge x = A sin(w t), and print
 * per step the body's six loads and each line's fairlead tension (%.17g).
 *
 *   moordyn_host FILE STEPS DT AMPLITUDE OMEGA
 *
 * The declarations are MoorDyn 2.7's C API (MoorDyn2.h), written out here: the wheel has the
 * library, not its headers.  Exit status: 0 done, 1 usage, 2 MoorDyn refused. */
#include <stdio.h>
#include <stdlib.h>
#include <math.h>

typedef struct __MoorDyn *MoorDyn;
typedef struct __MoorDynLine *MoorDynLine;
MoorDyn MoorDyn_Create(const char *infilename);
int MoorDyn_SetVerbosity(MoorDyn system, int verbosity);
int MoorDyn_NCoupledDOF(MoorDyn system, unsigned int *n);
int MoorDyn_Init(MoorDyn system, const double *x, const double *xd);
int MoorDyn_ExternalWaveKinInit(MoorDyn system, unsigned int *n);
int MoorDyn_ExternalWaveKinSet(MoorDyn system, const double *u, const double *ud, double t);
int MoorDyn_Step(MoorDyn system, const double *x, const double *xd, double *f, double *t, double *dt);
int MoorDyn_GetNumberLines(MoorDyn system, unsigned int *n);
MoorDynLine MoorDyn_GetLine(MoorDyn system, unsigned int l);
int MoorDyn_GetLineFairTen(MoorDynLine line, double *t);
int MoorDyn_Close(MoorDyn system);

#define ERR_LEVEL 3

int main(int argc, char **argv) {
    if (argc != 6) {
        fprintf(stderr, "usage: %s FILE STEPS DT AMPLITUDE OMEGA\n", argv[0]);
        return 1;
    }
    int steps = atoi(argv[2]);
    double dt = atof(argv[3]), amp = atof(argv[4]), w = atof(argv[5]);
    MoorDyn md = MoorDyn_Create(argv[1]);
    if (!md) return 2;
    MoorDyn_SetVerbosity(md, ERR_LEVEL);
    unsigned int dof = 0, points = 0, lines = 0;
    MoorDyn_NCoupledDOF(md, &dof);
    if (dof != 6) { fprintf(stderr, "expected one coupled body, found %u coupled dof\n", dof); return 2; }
    double x[6] = {0}, xd[6] = {0}, f[6];
    if (MoorDyn_Init(md, x, xd) != 0) return 2;
    MoorDyn_ExternalWaveKinInit(md, &points);
    double *u = calloc(3 * (size_t)points + 1, sizeof(double));   /* still water */
    MoorDyn_GetNumberLines(md, &lines);
    for (int k = 0; k < steps; k++) {
        double t = k * dt, h = dt;
        x[0] = amp * sin(w * t);
        xd[0] = amp * w * cos(w * t);
        MoorDyn_ExternalWaveKinSet(md, u, u, t + 0.5 * dt);
        if (MoorDyn_Step(md, x, xd, f, &t, &h) != 0) return 2;
        for (int i = 0; i < 6; i++) printf("%.17g ", f[i]);
        for (unsigned int l = 1; l <= lines; l++) {
            double ten = 0;
            MoorDyn_GetLineFairTen(MoorDyn_GetLine(md, l), &ten);
            printf("%.17g ", ten);
        }
        printf("\n");
    }
    free(u);
    MoorDyn_Close(md);
    return 0;
}
