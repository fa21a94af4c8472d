/* A cable-redundant master for the redundancy interop test (docs/topology.md, "Cable
 * redundancy"): SOEM v1.4.0 opened on two ports with ec_init_redundant (or, for the control
 * run, on the first port only with ec_init) brings the network to OP and exchanges process data
 * every millisecond, counting the cycles whose working counter is not the whole network's.
 * SOEM's own red_test has its ec_init_redundant call commented out, hence this client.
 * A separate program: built against SOEM's libsoem.a by the ctest fixture (build_soem.sh),
 * never linked into ecsim.
 *
 * usage: red_client IF1 IF2|- SECONDS
 * prints: "slaves N", "op wkc E" once every slave is in OP (or "not in OP: ..." and exit 4),
 *         "wkc W at cycle C" whenever the working counter changes, and at the end
 *         "done cycles C lost L" (L: cycles whose working counter was not E).
 * exit: 0 after SECONDS of cycles, 2 on bad arguments, 3 when no slave was found.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ethercat.h"

static char io_map[4096];

static void next_cycle(struct timespec *t)
{
   t->tv_nsec += 1000000;
   if (t->tv_nsec >= 1000000000)
   {
      t->tv_nsec -= 1000000000;
      t->tv_sec += 1;
   }
   clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, t, NULL);
}

int main(int argc, char *argv[])
{
   if (argc != 4)
   {
      fprintf(stderr, "usage: %s IF1 IF2|- SECONDS\n", argv[0]);
      return 2;
   }
   const int redundant = strcmp(argv[2], "-") != 0;
   const int seconds = atoi(argv[3]);
   const int opened = redundant ? ec_init_redundant(argv[1], argv[2]) : ec_init(argv[1]);
   if (!opened)
   {
      printf("init on %s failed\n", argv[1]);
      return 3;
   }
   if (ec_config_init(FALSE) <= 0)
   {
      printf("slaves 0\n");
      ec_close();
      return 3;
   }
   printf("slaves %d\n", ec_slavecount);
   ec_config_map(&io_map);
   ec_statecheck(0, EC_STATE_SAFE_OP, EC_TIMEOUTSTATE * 4);
   const int expected_wkc = (ec_group[0].outputsWKC * 2) + ec_group[0].inputsWKC;
   ec_slave[0].state = EC_STATE_OPERATIONAL;
   ec_send_processdata();
   ec_receive_processdata(EC_TIMEOUTRET);
   ec_writestate(0);
   for (int tries = 200; tries > 0 && ec_slave[0].state != EC_STATE_OPERATIONAL; --tries)
   {
      ec_send_processdata();
      ec_receive_processdata(EC_TIMEOUTRET);
      ec_statecheck(0, EC_STATE_OPERATIONAL, 50000);
   }
   if (ec_slave[0].state != EC_STATE_OPERATIONAL)
   {
      ec_readstate();
      for (int i = 1; i <= ec_slavecount; i++)
      {
         if (ec_slave[i].state != EC_STATE_OPERATIONAL)
         {
            printf("not in OP: slave %d state 0x%02x\n", i, ec_slave[i].state);
         }
      }
      ec_close();
      return 4;
   }
   printf("op wkc %d\n", expected_wkc);
   fflush(stdout);
   int lost = 0;
   int last_wkc = expected_wkc;
   const int cycles = seconds * 1000;
   struct timespec t;
   clock_gettime(CLOCK_MONOTONIC, &t);
   for (int c = 0; c < cycles; c++)
   {
      ec_send_processdata();
      const int wkc = ec_receive_processdata(EC_TIMEOUTRET);
      if (wkc != expected_wkc) lost++;
      if (wkc != last_wkc)
      {
         printf("wkc %d at cycle %d\n", wkc, c);
         fflush(stdout);
         last_wkc = wkc;
      }
      next_cycle(&t);
   }
   printf("done cycles %d lost %d\n", cycles, lost);
   ec_slave[0].state = EC_STATE_INIT;
   ec_writestate(0);
   ec_close();
   return 0;
}
